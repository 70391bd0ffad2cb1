// Config to plan: every key read by its row of the key table (config_keys.cpp), then the
// checks across keys, the stage chain and the megakernel's limits.
#include "wavetrace/setup/plan_render.hpp"

#include <algorithm>
#include <bit>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "wavetrace/stages/gather_spawn.hpp"
#include "wavetrace/stages/spawn.hpp"

namespace wavetrace {
namespace {

// The paper's in-core ray buffer (§4): 88 MB, reorder.buffer = disk's default.
constexpr std::size_t kPaperInCoreBufferBytes = 88'000'000;

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
  // [memory] observes the megakernel's trace calls (the paper's renderer without reordering:
  // each path's rays one after another); the look-ahead reads the wavefront's queued batches.
  if (plan.memory.look_ahead_batches > 0) {
    throw ConfigError(fmt::format("memory.look_ahead = {} reads the batches queued for trace: pipeline.mode = "
                                  "megakernel has none (set memory.look_ahead = 0 or pipeline.mode = wavefront)",
                                  plan.memory.look_ahead_batches));
  }
}

}  // namespace

std::size_t rays_per_camera_ray(const RenderPlan& plan) {
  if (plan.integrator == Integrator::photon) return GatherSpawnStage::rays_out_per_ray(plan.photon.gather_rays);
  return std::find(plan.stages.begin(), plan.stages.end(), "spawn") != plan.stages.end() ? SpawnStage::kRaysOutPerRay : 1;
}

void check_accelerator_options(const Config& config, const AcceleratorOptions& options) {
  // epsilon chooses the bits: both given (even bits = 16, the default) is a conflict.
  if ((config.given("accel.hmq.bits") && config.given("accel.hmq.epsilon")) ||
      (options.hmq.epsilon > 0.0 && options.hmq.bits != HmqOptions{}.bits)) {
    throw ConfigError(fmt::format("accel.hmq.bits = {} and accel.hmq.epsilon = {}: set one of them (epsilon "
                                  "chooses the bits)",
                                  options.hmq.bits, options.hmq.epsilon));
  }
  for (const auto& [key, width] : {std::pair{"accel.bvh.width", options.bvh.width},
                                   std::pair{"accel.raystrips.width", options.raystrips.width},
                                   std::pair{"accel.hmq.width", options.hmq.width}}) {
    if (width != 2 && width != 8) throw ConfigError(fmt::format("{} = {}: must be 2 or 8", key, width));
  }
  // A top share set for the wide layout, which has no float top, is refused, not ignored.
  if (options.hmq.width == 8 &&
      (config.given("accel.hmq.top_fraction") || options.hmq.top_fraction != HmqOptions{}.top_fraction)) {
    throw ConfigError(fmt::format("accel.hmq.top_fraction = {} applies to the binary layout (width 2): width 8 "
                                  "quantizes every node",
                                  options.hmq.top_fraction));
  }
  if (options.hmq.width == 2 && (config.given("accel.hmq.layout") || options.hmq.layout != HmqOptions{}.layout)) {
    throw ConfigError(fmt::format("accel.hmq.layout = {} orders the 8-wide nodes (width 8): the binary layout "
                                  "keeps its blocks",
                                  to_string(options.hmq.layout)));
  }
  if (options.hmq.width == 2 && options.hmq.leaves_beside_nodes) {
    throw ConfigError("accel.hmq.leaves_beside_nodes = true places the 8-wide nodes' leaves (width 8): the binary "
                      "layout keeps its blocks");
  }
}

void check_memory_plan(const Config& config, const MemoryPlan& plan) {
  if (!std::has_single_bit(plan.page_bytes)) {
    throw ConfigError(fmt::format("memory.page_bytes = {} is not a power of two", plan.page_bytes));
  }
  if (plan.file_backing && !plan.budget) {
    throw ConfigError("memory.backing = file pages a world file under memory.budget: set one (for example 20%)");
  }
  if (config.given("memory.look_ahead_threads") && plan.look_ahead_batches == 0) {
    throw ConfigError(fmt::format("memory.look_ahead_threads = {} reads ahead of trace only with memory.look_ahead, "
                                  "which is 0: set memory.look_ahead (for example 4)",
                                  plan.look_ahead_threads));
  }
  if (!plan.page_trace.empty() && !plan.file_backing) {
    throw ConfigError(fmt::format("memory.page_trace = '{}' records the pages of real paging: set memory.backing = "
                                  "file (and memory.budget)",
                                  plan.page_trace));
  }
  if (!plan.cache) return;
  if (plan.cache->name == "custom" && !(config.has("memory.cache_bytes") && config.has("memory.cache_ways"))) {
    throw ConfigError("memory.cache = 'custom' needs memory.cache_bytes and memory.cache_ways");
  }
  try {
    validate_cache_geometry(*plan.cache);
  } catch (const std::invalid_argument& error) {
    throw ConfigError(fmt::format("memory.cache: {}", error.what()));
  }
}

void read_plan_keys(const Config& config, RenderPlan& plan, std::string_view prefix) {
  for (const ConfigKey& row : config_schema()) {
    if (row.name.starts_with(prefix)) row.read(config, row.name, plan);
  }
}

void record_built_accelerator(Config& config, const RenderPlan& plan) {
  config.set_value("accel.type", plan.accelerator.type);
  const std::string section = "accel." + plan.accelerator.type + ".";
  for (const ConfigKey& key : config_schema()) {
    if (key.record == nullptr || !key.name.starts_with(section)) continue;
    if (const std::optional<ConfigValue> value = key.record(plan)) config.set_value(key.name, *value);
  }
}

AcceleratorOptions accelerator_options(const Config& config) {
  RenderPlan plan;
  read_plan_keys(config, plan, "accel.");
  read_plan_keys(config, plan, "build.");
  read_plan_keys(config, plan, "render.threads");
  check_accelerator_options(config, plan.accelerator);
  return plan.accelerator;
}

AccelGoal accel_goal(const Config& config) {
  RenderPlan plan;
  read_plan_keys(config, plan, "accel.");
  return plan.accel_goal;
}

MemoryPlan plan_memory(const Config& config) {
  RenderPlan plan;
  read_plan_keys(config, plan, "memory.");
  check_memory_plan(config, plan.memory);
  return plan.memory;
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
  if (plan.proxy.share_by_holding) {
    plan.proxy.share = plan.memory.budget ? ProxyOptions::kPagedShare : ProxyOptions::kInCoreShare;
  }
  if (config.given("reorder.buffer_rays") && config.has("reorder.buffer_bytes")) {
    throw ConfigError("reorder.buffer_rays and reorder.buffer_bytes both size the reorder buffer: set one of them");
  }
  if (plan.reorder.buffer == RayBufferKind::disk && !config.given("reorder.buffer_rays") &&
      !config.has("reorder.buffer_bytes")) {
    plan.reorder.buffer_rays = kPaperInCoreBufferBytes / ZSortStage::kBytesPerBufferedRay;  // the paper's in-core part
  }

  if (plan.stages == std::vector<std::string>{"auto"}) plan.stages = stages_for(plan.reorder.heuristic);
  if (std::count(plan.stages.begin(), plan.stages.end(), "auto") > 0) {
    throw ConfigError("pipeline.stages: 'auto' stands alone");
  }
  check_stage_order(plan.stages, plan.reorder.heuristic);
  // A disk buffer's in-core part fills with camera rays, each of which may become several.
  const std::size_t disk_buffer_budget = plan.reorder.buffer_rays * rays_per_camera_ray(plan);
  if (!config.has("render.rays_in_flight")) {
    plan.pipeline.rays_in_flight =
        plan.reorder.buffer == RayBufferKind::disk ? disk_buffer_budget
        : std::find(plan.stages.begin(), plan.stages.end(), "zsort") != plan.stages.end()
            ? plan.reorder.buffer_rays  // a full buffer alive at once: a flush sorts up to that many
            // Without a buffer to fill, rays in flight only keep the workers busy (4 batches of
            // camera rays each, and what they become); more would cost memory (and first-touch
            // page faults) for nothing.
            : 4 * std::size_t(worker_count(plan.pipeline)) * plan.pipeline.batch_size * rays_per_camera_ray(plan);
  }
  if (plan.reorder.buffer == RayBufferKind::disk) {
    if (std::find(plan.stages.begin(), plan.stages.end(), "zsort") == plan.stages.end()) {
      throw ConfigError("reorder.buffer = disk is zsort's buffer, and the chain has no zsort: set a reorder.heuristic");
    }
    if (plan.pipeline.rays_in_flight < disk_buffer_budget) {
      throw ConfigError(fmt::format("render.rays_in_flight = {} is under the disk buffer's in-core part ({} rays) "
                                    "times the {} rays each camera ray may become: the in-core part must be able "
                                    "to fill",
                                    plan.pipeline.rays_in_flight, plan.reorder.buffer_rays,
                                    rays_per_camera_ray(plan)));
    }
  }
  if (plan.integrator == Integrator::photon) {
    if (plan.pipeline.mode == PipelineMode::megakernel) {
      throw ConfigError("render.integrator = photon runs a photon pass and a camera pass through the stage graph: set "
                        "pipeline.mode = wavefront");
    }
    for (const char* needed : {"shade", "spawn"}) {
      if (std::find(plan.stages.begin(), plan.stages.end(), needed) == plan.stages.end()) {
        throw ConfigError(fmt::format("render.integrator = photon needs '{}' in pipeline.stages (photons bounce, and "
                                      "camera paths gather)",
                                      needed));
      }
    }
  }
  if (plan.pipeline.mode == PipelineMode::megakernel) check_megakernel_plan(plan);
  return plan;
}

}  // namespace wavetrace
