// `wavetrace bench pipeline`: does the wavefront pay for itself? The same image rendered by
// the megakernel (one path at a time) and by the wavefront with each reorder heuristic, in
// one run, at each thread count: render seconds, rays per second, each stage's nanoseconds
// per ray and share, the time spent outside trace, and whether every image is the
// megakernel's bit for bit.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/setup/config.hpp"
#include "wavetrace/stages/reorder_keys.hpp"

namespace wavetrace {

struct PipelineStageTime {
  std::string name;
  std::uint64_t rays = 0;  // rays in (generate: rays out)
  double seconds = 0.0;    // thread-seconds inside the stage
  double ns_per_ray() const { return rays > 0 ? seconds / double(rays) * 1e9 : 0.0; }
};

struct PipelineBenchResult {
  std::string mode;       // wavefront or megakernel
  std::string heuristic;  // the wavefront's reorder heuristic; "-" for the megakernel
  int threads = 0;
  std::vector<double> render_seconds;  // every repeat, in run order
  double median_seconds = 0.0;
  std::uint64_t rays_traced = 0;
  double mrays_per_s = 0.0;  // rays traced per wall second, at the median
  std::vector<PipelineStageTime> stages;  // of the median run (the megakernel's is one stage)
  // 1 - trace thread-seconds / (wall seconds x threads): every cost outside trace, idle time
  // and the graph's own included; absent for the megakernel, whose trace is not timed apart.
  std::optional<double> outside_trace_share;
  double speed_vs_megakernel = 0.0;  // the megakernel's median seconds (same threads) over this one's
  std::optional<double> thread_scaling;  // its median seconds at the fewest threads over this one's
  bool image_identical = false;           // to the megakernel's image
  // Where it is not: pixels with any channel different, and the summed absolute difference
  // over the megakernel image's sum. (Embree's stream kernels are not its rtcIntersect1's.)
  std::uint64_t pixels_differing = 0;
  double image_difference = 0.0;
};

struct PipelineBenchReport {
  std::string scene;
  std::size_t triangles = 0;
  std::string accel;
  std::string image;  // WxH, spp, depth
  std::optional<std::string> proxy;
  std::vector<PipelineBenchResult> results;
};

struct PipelineBenchRequest {
  std::vector<ReorderHeuristic> heuristics;  // the wavefront's, each against the megakernel
  std::vector<int> threads;                  // thread counts, each a full set of rows
  int repeats = 3;                           // renders per row; the median is reported
};

// `config` holds every other setting (scene, accel, render, proxy). Throws ConfigError for
// an empty request or [memory] observation (the megakernel cannot be observed).
PipelineBenchReport run_pipeline_bench(const Config& config, const PipelineBenchRequest& request);

nlohmann::json to_json(const PipelineBenchReport& report);
std::string to_table(const PipelineBenchReport& report);

}  // namespace wavetrace
