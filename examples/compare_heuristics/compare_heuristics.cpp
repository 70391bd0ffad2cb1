// One world, two renders: the same scene and accelerator rendered with reorder.heuristic =
// none and = hph (the hit point heuristic), and each stage's throughput printed from the
// stats render_image returns.
// Usage: compare_heuristics [SCENE] [--set section.key=value]...
#include <cstdio>
#include <string>
#include <vector>

#include <wavetrace/setup/render_setup.hpp>

int main(int argc, char** argv) {
  using namespace wavetrace;
  try {
    Config config;
    config.set("render.width=320");
    config.set("render.height=240");
    config.set("render.spp=2");
    for (int a = 1; a < argc; ++a) {
      const std::string argument = argv[a];
      if (argument == "--set" && a + 1 < argc) {
        config.set(argv[++a]);
      } else {
        config.set("scene.source=" + argument);
      }
    }
    // The world is built for the hph plan, whose chain needs the proxy; the other chain
    // (generate, trace, shade, spawn) leaves the proxy unused.
    config.set("reorder.heuristic=hph");
    const RenderPlan hph = plan_render(config);
    const BuiltWorld built(hph);
    config.set("reorder.heuristic=none");
    RenderPlan none = plan_render(config);
    none.accelerator = built.plan().accelerator;  // as built (auto's choice, if auto)

    std::printf("%s: %zu triangles, accelerator %s, %ux%u at %u spp\n", built.scene().name.c_str(),
                built.scene().triangle_count, built.world().accelerator.name().c_str(), hph.image.width,
                hph.image.height, hph.image.samples_per_pixel);
    double trace_speed[2] = {0.0, 0.0};
    const RenderPlan* plans[2] = {&none, &built.plan()};
    for (int k = 0; k < 2; ++k) {
      const RenderOutput output = render_image(*plans[k], built.world(), built.camera());
      std::printf("reorder.heuristic = %s: %.3f s wall on %d threads\n", to_string(plans[k]->reorder.heuristic).c_str(),
                  output.run.seconds, output.run.threads);
      for (const StageStats& stage : output.run.stages) {
        std::printf("  %-12s %10llu rays in %8.3f s  %7.2f Mrays/s per thread\n", stage.name.c_str(),
                    static_cast<unsigned long long>(stage.rays_in), stage.seconds, stage.mrays_per_s());
        if (stage.name == "trace") trace_speed[k] = stage.mrays_per_s();
      }
    }
    std::printf("trace with hph: %.2fx its speed without reordering\n",
                trace_speed[0] > 0.0 ? trace_speed[1] / trace_speed[0] : 0.0);
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "compare_heuristics: error: %s\n", error.what());
    return 1;
  }
}
