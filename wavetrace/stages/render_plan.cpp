// Config to plan: the key table's rows, then the checks across keys and the chain.
#include "wavetrace/stages/render_plan.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/info.h>

#include "wavetrace/stages/plan_keys.hpp"

namespace wavetrace {
namespace {

void check_stage_order(const std::vector<std::string>& names, ReorderHeuristic heuristic) {
  const auto position = [&](std::string_view name) {
    return std::find(names.begin(), names.end(), name) - names.begin();
  };
  const auto present = [&](std::string_view name) { return position(name) < std::ptrdiff_t(names.size()); };
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (std::count(names.begin(), names.end(), names[i]) > 1) {
      throw ConfigError(fmt::format("pipeline.stages: '{}' appears more than once", names[i]));
    }
  }
  if (names.empty() || names.front() != "generate") {
    throw ConfigError("pipeline.stages: must start with 'generate'");
  }
  if (present("shade") && (!present("trace") || position("trace") > position("shade"))) {
    throw ConfigError("pipeline.stages: 'shade' needs 'trace' before it");
  }
  if (present("spawn") && (!present("shade") || position("shade") > position("spawn"))) {
    throw ConfigError("pipeline.stages: 'spawn' needs 'shade' before it");
  }
  if (present("approx_hit") && (!present("trace") || position("approx_hit") > position("trace"))) {
    throw ConfigError("pipeline.stages: 'approx_hit' needs 'trace' after it");
  }
  if (present("zsort") && (!present("trace") || position("zsort") > position("trace"))) {
    throw ConfigError("pipeline.stages: 'zsort' needs 'trace' after it");
  }
  if (present("repack") && (!present("trace") || position("repack") > position("trace"))) {
    throw ConfigError("pipeline.stages: 'repack' needs 'trace' after it");
  }
  if (present("repack") && present("zsort")) {
    throw ConfigError("pipeline.stages: 'repack' and 'zsort' both buffer rays: use one (zsort's batches are full)");
  }
  if (present("zsort") && present("approx_hit") && position("approx_hit") > position("zsort")) {
    throw ConfigError("pipeline.stages: 'approx_hit' must come before 'zsort' (zsort sorts by its points)");
  }
  if (uses_hit_points(heuristic) && present("zsort") && !present("approx_hit")) {
    throw ConfigError(fmt::format("pipeline.stages: reorder.heuristic = '{}' needs 'approx_hit' before 'zsort'",
                                  to_string(heuristic)));
  }
  if (present("spawn") && names.back() != "spawn") {
    throw ConfigError("pipeline.stages: 'spawn' must be last (its rays go back to the start of the chain)");
  }
}


// The megakernel runs generate, trace, shade and spawn one path at a time: settings that
// only the wavefront can honour are refused rather than ignored.
void check_megakernel_plan(const RenderPlan& plan) {
  if (plan.reorder.heuristic != ReorderHeuristic::none) {
    throw ConfigError(fmt::format("reorder.heuristic = '{}' reorders batches of rays: pipeline.mode = megakernel has "
                                  "none (set reorder.heuristic = none or pipeline.mode = wavefront)",
                                  to_string(plan.reorder.heuristic)));
  }
  const std::vector<std::string> chain = {"generate", "trace", "shade", "spawn"};
  if (plan.stages != chain) {
    throw ConfigError(fmt::format("pipeline.stages = [{}]: pipeline.mode = megakernel runs generate, trace, shade, "
                                  "spawn (set pipeline.stages = auto)",
                                  fmt::join(plan.stages, ", ")));
  }
  if (plan.memory.enabled()) {
    throw ConfigError("[memory] observation (pager, cache) counts the wavefront's stages: set pipeline.mode = wavefront");
  }
}

}  // namespace

int worker_count(const PipelineOptions& options) {
  return options.threads > 0 ? options.threads : tbb::info::default_concurrency();
}

RenderPlan plan_render(const Config& config) {
  RenderPlan plan;
  read_plan_keys(config, plan);
  if (std::uint64_t(plan.image.width) * plan.image.height * plan.image.samples_per_pixel > (std::uint64_t{1} << 40)) {
    throw ConfigError("render: width x height x spp is over 2^40 rays");
  }
  if ((std::uint64_t(plan.image.seed) + 1) * plan.image.samples_per_pixel > std::numeric_limits<std::uint32_t>::max()) {
    throw ConfigError(fmt::format("render.seed = {} with render.spp = {}: the sample numbers, up to (seed + 1) x spp, "
                                  "must stay under 2^32",
                                  config.integer("render.seed"), plan.image.samples_per_pixel));
  }
  check_accelerator_options(config, plan.accelerator);
  check_memory_plan(config, plan.memory);
  // The proxy's accelerator takes the main one's options, of its own type (proxy.accel).
  const std::string proxy_type = plan.proxy.accelerator.type;
  plan.proxy.accelerator = plan.accelerator;
  plan.proxy.accelerator.type = proxy_type;
  if (config.given("reorder.buffer_rays") && config.has("reorder.buffer_bytes")) {
    throw ConfigError("reorder.buffer_rays and reorder.buffer_bytes both size the reorder buffer: set one of them");
  }

  if (plan.stages == std::vector<std::string>{"auto"}) plan.stages = stages_for(plan.reorder.heuristic);
  if (std::count(plan.stages.begin(), plan.stages.end(), "auto") > 0) {
    throw ConfigError("pipeline.stages: 'auto' stands alone");
  }
  check_stage_order(plan.stages, plan.reorder.heuristic);
  if (!config.has("render.rays_in_flight")) {
    plan.pipeline.rays_in_flight =
        std::find(plan.stages.begin(), plan.stages.end(), "zsort") != plan.stages.end()
            ? plan.reorder.buffer_rays  // so that the buffer can fill
            // Without a buffer to fill, rays in flight only keep the workers busy; more would
            // cost memory (and first-touch page faults) for nothing.
            : 4 * std::size_t(worker_count(plan.pipeline)) * plan.pipeline.batch_size;
  }
  if (plan.pipeline.mode == PipelineMode::megakernel) check_megakernel_plan(plan);
  return plan;
}

bool RenderPlan::needs_proxy() const { return std::find(stages.begin(), stages.end(), "approx_hit") != stages.end(); }

std::vector<std::string> stages_for(ReorderHeuristic heuristic) {
  std::vector<std::string> stages = {"generate"};
  if (uses_hit_points(heuristic)) stages.push_back("approx_hit");
  if (heuristic != ReorderHeuristic::none) stages.push_back("zsort");
  stages.insert(stages.end(), {"trace", "shade", "spawn"});
  return stages;
}

}  // namespace wavetrace
