// One world, every mode and heuristic rendered `repeats` times at each thread count,
// interleaved so that the machine's drift falls on all rows alike.
#include "wavetrace/bench/json_fields.hpp"
#include "wavetrace/bench/pipeline_bench.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "wavetrace/bench/render_world.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {
namespace {

struct Row {
  PipelineMode mode;
  ReorderHeuristic heuristic;
  int threads;
  std::vector<RenderOutput> runs;
};

PipelineBenchResult summarize(Row& row) {
  PipelineBenchResult result;
  result.mode = to_string(row.mode);
  result.heuristic = row.mode == PipelineMode::megakernel ? "-" : to_string(row.heuristic);
  result.threads = row.threads;
  std::vector<std::size_t> order(row.runs.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = i;
    result.render_seconds.push_back(row.runs[i].run.seconds);
  }
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return row.runs[a].run.seconds < row.runs[b].run.seconds; });
  const RenderOutput& median = row.runs[order[order.size() / 2]];
  result.median_seconds = median.run.seconds;
  double trace_seconds = 0.0;
  for (const StageStats& stage : median.run.stages) {
    const std::uint64_t rays = stage.name == "generate" ? stage.rays_out : stage.rays_in;
    result.stages.push_back({stage.name, rays, stage.seconds});
    if (stage.name == "trace" || stage.name == "megakernel") result.rays_traced = stage.rays_in;
    if (stage.name == "trace") trace_seconds = stage.seconds;
  }
  result.mrays_per_s = double(result.rays_traced) / result.median_seconds * 1e-6;
  if (row.mode == PipelineMode::wavefront) {
    result.outside_trace_share = 1.0 - trace_seconds / (median.run.seconds * median.run.threads);
  }
  return result;
}

}  // namespace

PipelineBenchReport run_pipeline_bench(const Config& config, const PipelineBenchRequest& request) {
  if (request.heuristics.empty()) throw ConfigError("--heuristics names no heuristic");
  if (request.threads.empty()) throw ConfigError("--threads names no thread count");
  if (request.repeats < 1) throw ConfigError("--repeat must be at least 1");
  for (int threads : request.threads) {
    if (threads < 0) throw ConfigError(fmt::format("--threads {}: must be 0 (all cores) or more", threads));
  }
  const RenderPlan base = plan_render(heuristic_variant(config, request.heuristics.front()));
  if (base.memory.enabled()) {
    throw ConfigError("bench pipeline compares with the megakernel, which [memory] observation cannot see: "
                      "use bench reorder for pager and cache counts");
  }
  bool hit_points = false;
  for (ReorderHeuristic heuristic : request.heuristics) hit_points = hit_points || uses_hit_points(heuristic);
  const RenderWorld opened(base, hit_points);
  const World world = opened.world();
  const Camera camera = resolve_camera(base.camera, opened.scene());

  PipelineBenchReport report;
  report.scene = opened.scene().name;
  report.triangles = opened.scene().triangle_count;
  report.accel = opened.accelerator().name();
  report.image = fmt::format("{}x{}, {} spp, depth {}", base.image.width, base.image.height,
                             base.image.samples_per_pixel, base.rules.max_depth);
  if (const Proxy* proxy = opened.proxy()) {
    report.proxy = fmt::format("{} triangles by {} on {}", proxy->report().triangles, to_string(proxy->report().method),
                               proxy->accelerator().name());
  }

  std::vector<Row> rows;
  for (int threads : request.threads) {
    rows.push_back({PipelineMode::megakernel, ReorderHeuristic::none, threads, {}});
    for (ReorderHeuristic heuristic : request.heuristics) rows.push_back({PipelineMode::wavefront, heuristic, threads, {}});
  }
  std::vector<float> megakernel_image;
  for (int repeat = 0; repeat < request.repeats; ++repeat) {
    for (Row& row : rows) {
      Config variant = heuristic_variant(config, row.heuristic);
      variant.set_value("pipeline.mode", to_string(row.mode));
      variant.set("render.threads=" + std::to_string(row.threads));
      RenderOutput output = render_image(plan_render(variant), world, camera);
      if (megakernel_image.empty()) megakernel_image = output.image;
      if (repeat > 0) output.image.clear();  // the first repeat's image stands for the row
      row.runs.push_back(std::move(output));
    }
  }

  std::map<int, double> megakernel_seconds;  // by thread count
  std::map<std::string, double> fewest_threads_seconds;  // by mode and heuristic
  const int fewest = *std::min_element(request.threads.begin(), request.threads.end());
  for (Row& row : rows) {
    PipelineBenchResult result = summarize(row);
    const std::vector<float>& image = row.runs.front().image;
    result.image_identical = image == megakernel_image;
    double difference = 0.0, total = 0.0;
    for (std::size_t p = 0; p + 2 < image.size(); p += 3) {
      bool differs = false;
      for (std::size_t c = p; c < p + 3; ++c) {
        differs = differs || image[c] != megakernel_image[c];
        difference += std::fabs(double(image[c]) - double(megakernel_image[c]));
        total += std::fabs(double(megakernel_image[c]));
      }
      result.pixels_differing += differs;
    }
    result.image_difference = total > 0.0 ? difference / total : 0.0;
    if (row.mode == PipelineMode::megakernel) megakernel_seconds[row.threads] = result.median_seconds;
    result.speed_vs_megakernel = megakernel_seconds[row.threads] / result.median_seconds;
    const std::string key = result.mode + "/" + result.heuristic;
    if (row.threads == fewest) fewest_threads_seconds[key] = result.median_seconds;
    if (row.threads != fewest) result.thread_scaling = fewest_threads_seconds[key] / result.median_seconds;
    report.results.push_back(std::move(result));
  }
  return report;
}

nlohmann::json to_json(const PipelineBenchReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const PipelineBenchResult& r : report.results) {
    nlohmann::json stages = nlohmann::json::array();
    const double thread_seconds = r.median_seconds * r.threads;
    for (const PipelineStageTime& stage : r.stages) {
      stages.push_back({{"name", stage.name},
                        {"rays", stage.rays},
                        {"seconds", stage.seconds},
                        {"ns_per_ray", stage.ns_per_ray()},
                        {"share", stage.seconds / thread_seconds}});
    }
    results.push_back({{"mode", r.mode},
                       {"heuristic", r.heuristic},
                       {"threads", r.threads},
                       {"render_seconds", r.render_seconds},
                       {"median_seconds", r.median_seconds},
                       {"rays_traced", r.rays_traced},
                       {"mrays_per_s", r.mrays_per_s},
                       {"stages", stages},
                       {"outside_trace_share", json_or_null(r.outside_trace_share)},
                       {"speed_vs_megakernel", r.speed_vs_megakernel},
                       {"thread_scaling", json_or_null(r.thread_scaling)},
                       {"image_identical", r.image_identical},
                       {"pixels_differing", r.pixels_differing},
                       {"image_difference", r.image_difference}});
  }
  return {{"scene", {{"source", report.scene}, {"triangles", report.triangles}}},
          {"accel", report.accel},
          {"image", report.image},
          {"proxy", json_or_null(report.proxy)},
          {"results", results}};
}

std::string to_table(const PipelineBenchReport& report) {
  std::string table = fmt::format("{}: {} triangles; {} on {}\n", report.scene, report.triangles, report.image, report.accel);
  if (report.proxy) table += "proxy: " + *report.proxy + "\n";
  const std::vector<std::string> stage_names = {"generate", "approx_hit", "zsort", "trace", "shade", "spawn"};
  table += fmt::format("{:<11} {:<11} {:>3} {:>9} {:>8}", "mode", "heuristic", "thr", "render s", "Mrays/s");
  for (const std::string& name : stage_names) table += fmt::format(" {:>10}", name.substr(0, 10));
  table += fmt::format(" {:>8} {:>8} {:>8}  {}\n", "outside", "vs mega", "scaling", "identical");
  for (const PipelineBenchResult& r : report.results) {
    table += fmt::format("{:<11} {:<11} {:>3} {:>9.3f} {:>8.2f}", r.mode, r.heuristic, r.threads, r.median_seconds,
                         r.mrays_per_s);
    for (const std::string& name : stage_names) {
      const auto stage = std::find_if(r.stages.begin(), r.stages.end(), [&](const auto& s) { return s.name == name; });
      table += stage == r.stages.end() ? fmt::format(" {:>10}", "-") : fmt::format(" {:>10.1f}", stage->ns_per_ray());
    }
    table += fmt::format(" {:>8} {:>7.2f}x {:>8}  {}\n",
                         r.outside_trace_share ? fmt::format("{:.1f}%", 100.0 * *r.outside_trace_share) : "-",
                         r.speed_vs_megakernel, r.thread_scaling ? fmt::format("{:.2f}x", *r.thread_scaling) : "-",
                         r.image_identical ? std::string("yes")
                                           : fmt::format("NO ({} px, {:.2g} of the light)", r.pixels_differing,
                                                         r.image_difference));
  }
  table += "stage columns: nanoseconds per ray the stage saw (thread-seconds / rays in; generate: rays out)\n"
           "outside: 1 - trace thread-seconds / (render s x threads); vs mega: the megakernel's render s over this\n"
           "row's at the same threads; scaling: this row's render s at the fewest threads over this one's\n";
  return table;
}

}  // namespace wavetrace
