// `wavetrace render`: config and flags to a plan, scene and accelerator to an image.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <new>

#include <fmt/format.h>

#include "accel/registry.hpp"
#include "app/commands.hpp"
#include "app/image_output.hpp"
#include "app/progress_line.hpp"
#include "app/render_report.hpp"
#include "memory/process_memory.hpp"
#include "scene/lights.hpp"
#include "stages/render_setup.hpp"
#include "stages/world_file.hpp"

namespace wavetrace {
namespace {

struct RenderArguments {
  std::string scene;
  std::string accel;
  int spp = 0;
  std::string size;
  int threads = -1;
  std::string config_file;
  std::vector<std::string> assignments;
  std::string out = "out/render.exr";
  std::string stats;
};

Config build_config(const RenderArguments& args) {
  Config config;
  if (!args.config_file.empty()) config.load_file(args.config_file);
  if (!args.scene.empty()) config.set_value("scene.source", args.scene);
  if (!args.accel.empty()) config.set_value("accel.type", args.accel);
  if (args.spp != 0) config.set_value("render.spp", std::int64_t{args.spp});
  if (args.threads >= 0) config.set_value("render.threads", std::int64_t{args.threads});
  if (!args.size.empty()) {
    const std::size_t x = args.size.find('x');
    if (x == std::string::npos) throw ConfigError(fmt::format("--size '{}': expected WIDTHxHEIGHT", args.size));
    config.set("render.width=" + args.size.substr(0, x));
    config.set("render.height=" + args.size.substr(x + 1));
  }
  for (const std::string& assignment : args.assignments) config.set(assignment);
  return config;
}

// Renders through the pipeline and writes the image, the report and the stats.
int finish_render(const RenderArguments& args, const RenderPlan& plan, const Scene& scene, const World& world,
                  const Camera& camera, RenderPhases measured, const AccelChoice* choice = nullptr) {
  ProgressLine progress(stderr);
  const RenderOutput output =
      render_image(plan, world, camera, progress.enabled() ? [&](const Progress& p) { progress.update(p); }
                                                          : std::function<void(const Progress&)>());
  progress.finish();
  measured.after_render_bytes = read_resident_memory().current_bytes;
  measured.peak_rss_bytes = read_resident_memory().peak_bytes;

  write_exr(args.out, plan.image.width, plan.image.height, output.image);
  const std::string preview = preview_path_for(args.out);
  write_png_preview(preview, plan.image.width, plan.image.height, output.image);

  const RenderFacts facts{scene, world.accelerator, plan, output, args.out, world.proxy, measured, choice};
  fmt::print("{}: {} triangles, {} vertices{}\n", scene.name, scene.triangle_count, scene.vertex_count,
             scene.cleanup.degenerate_dropped ? fmt::format(", {} degenerate dropped", scene.cleanup.degenerate_dropped)
                                              : std::string());
  fmt::print("{}", render_table(facts));
  fmt::print("wrote {} and {}\n", args.out, preview);
  if (!args.stats.empty()) {
    std::ofstream file(args.stats);
    file << render_stats_json(facts).dump(2) << "\n";
    if (!file) throw std::runtime_error(fmt::format("{}: could not write stats", args.stats));
  }
  return 0;
}

// A saved world: mapped (or paged from disk under memory.budget) and traced as built.
int render_world(const RenderArguments& args, RenderPlan plan) {
  RenderPhases measured;
  const std::unique_ptr<LoadedWorld> world_file = load_world(plan.scene.source, world_paging(plan), plan.pipeline.threads);
  LoadedWorld& loaded = *world_file;
  measured.load_seconds = loaded.seconds;
  measured.after_load_bytes = measured.after_build_bytes = read_resident_memory().current_bytes;
  plan.accelerator.type = loaded.type;
  if (plan.needs_proxy() && !loaded.proxy) {
    throw ConfigError(fmt::format("{} was saved without a proxy, which the chain's approx_hit needs: build it with --proxy",
                                  plan.scene.source));
  }
  const Camera camera = resolve_camera(plan.camera, loaded.scene);
  const World world{loaded.scene, *loaded.accelerator, *loaded.lights, plan.needs_proxy() ? loaded.proxy.get() : nullptr,
                    loaded.file->pager()};
  return finish_render(args, plan, loaded.scene, world, camera, measured);
}

int render_scene(const RenderPlan& requested, const RenderArguments& args, std::string& activity) {
  RenderPhases measured;
  RenderPlan plan = requested;
  activity = fmt::format("loading {}", plan.scene.source);
  const auto load_start = std::chrono::steady_clock::now();
  SceneForWorld loaded = load_scene_for_world(plan, plan.needs_proxy());
  Scene& scene = loaded.scene;
  const Camera& camera = loaded.camera;
  const ResolvedAccelerator& resolved = loaded.accelerator;
  plan.accelerator = resolved.options;
  if (const std::string line = resolution_summary(resolved); !line.empty()) fmt::print("{}\n", line);
  measured.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  measured.after_load_bytes = read_resident_memory().current_bytes;
  activity = fmt::format("building '{}' over {} triangles", plan.accelerator.type, scene.triangle_count);
  const std::unique_ptr<Accelerator> accelerator = build_world_accelerator(scene, plan.accelerator);
  const LightSampler lights = represented_lights(scene, *accelerator);
  activity = fmt::format("building the proxy of {} triangles", scene.triangle_count);
  const std::unique_ptr<Proxy> proxy = build_proxy(plan, scene, *accelerator);
  if (holds_own_geometry(plan.accelerator.type)) scene.release_mesh();
  measured.after_build_bytes = read_resident_memory().current_bytes;
  const World world{scene, *accelerator, lights, proxy.get()};
  activity = fmt::format("rendering {}x{} at {} spp", plan.image.width, plan.image.height, plan.image.samples_per_pixel);
  return finish_render(args, plan, scene, world, camera, measured, resolved.choice ? &*resolved.choice : nullptr);
}

int run_render(const RenderArguments& args) {
  const Config config = build_config(args);
  const RenderPlan plan = plan_render(config);
  // What was being done, so that running out of memory says where (and not "bad_alloc").
  std::string activity = fmt::format("loading the world {}", plan.scene.source);
  try {
    if (is_world_file(plan.scene.source)) return render_world(args, plan);
    if (plan.memory.file_backing) {
      throw ConfigError(fmt::format(
          "memory.backing = file pages a world file; {} is not one (make one with wavetrace build)", plan.scene.source));
    }
    return render_scene(plan, args, activity);
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(fmt::format("out of memory {} ({:.2f} GB resident at most, {:.2f} GB available now)",
                                         activity, double(read_resident_memory().peak_bytes) * 1e-9,
                                         double(available_memory_bytes()) * 1e-9));
  }
}

}  // namespace

void add_render_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RenderArguments>();
  CLI::App* command = app.add_subcommand("render", "path-trace an image through the stage pipeline");
  command->add_option("scene,--scene", args->scene,
                      "mesh file, scene file (.toml), builtin:NAME[:TRIANGLES] or a saved world (.wtw) (default builtin:default)");
  command->add_option("--accel", args->accel, "accelerator (accel.type)");
  command->add_option("--spp", args->spp, "samples per pixel (render.spp)");
  command->add_option("--size", args->size, "image size as WIDTHxHEIGHT");
  command->add_option("--threads", args->threads, "worker threads, 0 = all cores (render.threads)");
  command->add_option("--config", args->config_file, "TOML config file");
  command->add_option("--set", args->assignments, "override a config key: section.key=value")->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  command->add_option("--out", args->out, "OpenEXR output; a PNG preview is written beside it");
  command->add_option("--stats", args->stats, "write run statistics as JSON");
  command->callback([args, &exit_code] { exit_code = run_render(*args); });
}

}  // namespace wavetrace
