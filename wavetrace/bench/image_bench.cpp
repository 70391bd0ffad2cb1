// Renders one image per accelerator with identical settings (renders are deterministic, so
// any difference is the accelerator's) and measures each against the first.
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/bench/image_bench.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {

ImageBenchReport run_image_bench(const Config& config, std::vector<AcceleratorSpec> accelerators, bool noise_floor) {
  if (accelerators.empty()) throw ConfigError("--accel names no accelerator");
  const RenderPlan plan = plan_render(config);
  const Scene scene = load_scene(plan.scene);
  for (AcceleratorSpec& spec : accelerators) resolve_accelerator_spec(spec, scene, config);
  // The Monte Carlo noise: the reference again with the next seed's samples.
  RenderPlan reseeded = plan;
  ++reseeded.image.seed;
  std::vector<std::pair<const AcceleratorSpec*, const RenderPlan*>> renders;
  for (const AcceleratorSpec& spec : accelerators) renders.emplace_back(&spec, &plan);
  if (noise_floor) renders.emplace_back(&accelerators.front(), &reseeded);
  const Camera camera = resolve_camera(plan.camera, scene);
  ImageBenchReport report;
  report.scene = scene.name;
  report.triangles = scene.mesh.triangle_count();
  report.image = fmt::format("{}x{}, {} spp, depth {}", plan.image.width, plan.image.height,
                             plan.image.samples_per_pixel, plan.rules.max_depth);
  std::vector<float> reference;
  double reference_mean = 0.0;
  for (const auto& [spec, render_plan] : renders) {
    // Hits carry the surface the accelerator answers for: a lossy one's renders shade it.
    const auto accelerator = build_world_accelerator(scene, spec->options);
    const LightSampler lights = represented_lights(scene, *accelerator);
    const World world{scene, *accelerator, lights, nullptr};
    const RenderOutput output = render_image(*render_plan, world, camera);
    report.threads = output.run.threads;
    ImageBenchResult result;
    result.label = render_plan == &plan ? spec->label : fmt::format("{}, seed {}", spec->label, render_plan->image.seed);
    result.noise_floor = render_plan != &plan;
    result.bytes_per_triangle = double(accelerator->memory().total()) / double(scene.mesh.triangle_count());
    result.build_seconds = accelerator->build().seconds;
    result.render_seconds = output.run.seconds;
    result.closest_mrays_per_s = output.closest_mrays_per_s;
    result.notes = accelerator->build_notes();
    if (reference.empty()) {
      reference = output.image;
      for (const float value : reference) reference_mean += value;
      reference_mean /= double(std::max<std::size_t>(1, reference.size()));
    } else {
      double sum = 0.0;
      for (std::size_t i = 0; i < reference.size(); ++i) {
        const double difference = double(output.image[i]) - double(reference[i]);
        sum += difference * difference;
        result.max_difference = std::max(result.max_difference, std::fabs(difference));
      }
      result.rmse = std::sqrt(sum / double(std::max<std::size_t>(1, reference.size())));
      result.relative_rmse = reference_mean > 0.0 ? result.rmse / reference_mean : 0.0;
    }
    report.results.push_back(result);
  }
  return report;
}

nlohmann::json to_json(const ImageBenchReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const ImageBenchResult& r : report.results) {
    results.push_back({{"accel", r.label},
                       {"bytes_per_triangle", r.bytes_per_triangle},
                       {"build_seconds", r.build_seconds},
                       {"render_seconds", r.render_seconds},
                       {"closest_mrays_per_s", r.closest_mrays_per_s},
                       {"rmse", r.rmse},
                       {"relative_rmse", r.relative_rmse},
                       {"max_difference", r.max_difference},
                       {"build_notes", r.notes},
                       {"noise_floor", r.noise_floor}});
  }
  return {{"scene", {{"source", report.scene}, {"triangles", report.triangles}}},
          {"image", report.image},
          {"threads", report.threads},
          {"reference", report.results.empty() ? std::string() : report.results.front().label},
          {"results", results}};
}

std::string to_table(const ImageBenchReport& report) {
  std::string table = fmt::format("{}: {} triangles; {}; {} threads; RMSE against the first image\n", report.scene,
                                  report.triangles, report.image, report.threads);
  table += fmt::format("{:<28} {:>8} {:>9} {:>9} {:>11} {:>11} {:>10} {:>10}\n", "accel", "B/tri", "build s",
                       "render s", "closest Mr/s", "RMSE", "rel RMSE", "max diff");
  for (const ImageBenchResult& r : report.results) {
    table += fmt::format("{:<28} {:>8.2f} {:>9.3f} {:>9.3f} {:>11.2f} {:>11.3e} {:>10.3e} {:>10.3e}\n", r.label,
                         r.bytes_per_triangle, r.build_seconds, r.render_seconds, r.closest_mrays_per_s, r.rmse,
                         r.relative_rmse, r.max_difference);
  }
  return table;
}

}  // namespace wavetrace
