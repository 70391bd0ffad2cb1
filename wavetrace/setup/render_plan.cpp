// The plan's derived answers: the chain auto stands for, the worker count, whether a proxy is needed.
#include "wavetrace/setup/render_plan.hpp"

#include <algorithm>
#include <stdexcept>

#include <tbb/info.h>

namespace wavetrace {

int worker_count(const PipelineOptions& options) {
  return options.threads > 0 ? options.threads : tbb::info::default_concurrency();
}

bool RenderPlan::needs_proxy() const { return std::find(stages.begin(), stages.end(), "approx_hit") != stages.end(); }

std::vector<std::string> stages_for(ReorderHeuristic heuristic) {
  std::vector<std::string> stages = {"generate"};
  if (uses_hit_points(heuristic)) stages.push_back("approx_hit");
  if (heuristic != ReorderHeuristic::none) stages.push_back("zsort");
  stages.insert(stages.end(), {"trace", "shade", "spawn"});
  return stages;
}

DistributeMode parse_distribute_mode(const std::string& text) {
  if (text == "image") return DistributeMode::image;
  if (text == "data") return DistributeMode::data;
  throw std::invalid_argument("unknown distribute mode '" + text + "' (image, data)");
}

std::string to_string(DistributeMode mode) { return mode == DistributeMode::image ? "image" : "data"; }

DistributeBalance parse_distribute_balance(const std::string& text) {
  if (text == "bytes") return DistributeBalance::bytes;
  if (text == "triangles") return DistributeBalance::triangles;
  if (text == "rays") return DistributeBalance::rays;
  throw std::invalid_argument("unknown distribute balance '" + text + "' (bytes, triangles, rays)");
}

std::string to_string(DistributeBalance balance) {
  switch (balance) {
    case DistributeBalance::bytes: return "bytes";
    case DistributeBalance::triangles: return "triangles";
    case DistributeBalance::rays: return "rays";
  }
  return "bytes";
}

}  // namespace wavetrace
