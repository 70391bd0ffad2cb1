// The key table: each config key, the plan field it sets and how its value is read.
#include "wavetrace/stages/plan_keys.hpp"

#include <bit>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>

namespace wavetrace {
namespace {

// The plan field a path of member pointers names: field<&RenderPlan::image, &ImageSpec::width>.
template <auto... Path>
auto& field(RenderPlan& plan) {
  return (plan.*....*Path);
}

template <auto... Path>
void integer(const Config& config, std::string_view key, RenderPlan& plan) {
  auto& target = field<Path...>(plan);
  target = static_cast<std::remove_cvref_t<decltype(target)>>(config.integer(key));
}

template <auto... Path>
void real(const Config& config, std::string_view key, RenderPlan& plan) {
  auto& target = field<Path...>(plan);
  target = static_cast<std::remove_cvref_t<decltype(target)>>(config.real(key));
}

template <auto... Path>
void boolean(const Config& config, std::string_view key, RenderPlan& plan) {
  field<Path...>(plan) = config.boolean(key);
}

template <auto... Path>
void text(const Config& config, std::string_view key, RenderPlan& plan) {
  field<Path...>(plan) = config.text(key);
}

// A text key with listed choices, to its enum.
template <auto Parse, auto... Path>
void choice(const Config& config, std::string_view key, RenderPlan& plan) {
  field<Path...>(plan) = Parse(config.text(key));
}

// Keys without a default: the override is set only when the key is.
template <auto... Path>
void optional_vector3(const Config& config, std::string_view key, RenderPlan& plan) {
  if (config.has(key)) field<Path...>(plan) = config.vector3(key);
}

template <auto... Path>
void optional_float(const Config& config, std::string_view key, RenderPlan& plan) {
  if (config.has(key)) field<Path...>(plan) = static_cast<float>(config.real(key));
}

template <auto... Path>
void optional_size(const Config& config, std::string_view key, RenderPlan& plan) {
  if (config.has(key)) field<Path...>(plan) = static_cast<std::size_t>(config.integer(key));
}

using P = RenderPlan;
using A = AcceleratorOptions;

// Keys that set more than one field, or read a word or a unit, spelled out.
void read_threads(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.pipeline.threads = static_cast<int>(config.integer(key));
  plan.accelerator.embree.threads = plan.pipeline.threads;  // Embree's builder runs on as many
}
void read_film(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.film_per_thread = config.text(key) == "per_thread";
}
void read_accel_type(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.accelerator.type = config.text(key);
  plan.accel_goal.automatic = plan.accelerator.type == "auto";
}
void read_max_error(const Config& config, std::string_view key, RenderPlan& plan) {
  // "pixel" (no number): half a pixel's footprint, resolved against the camera later.
  plan.accel_goal.max_error = config.word(key) ? std::nullopt : std::optional<double>(config.real(key));
}
void read_bins(const Config& config, std::string_view key, RenderPlan& plan) {
  const auto bins = static_cast<std::uint32_t>(config.integer(key));
  plan.accelerator.bvh.bins = plan.accelerator.raystrips.bins = plan.accelerator.hmq.bins = bins;  // every SAH build's
}
void read_hmq_epsilon(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.accel_goal.hmq_epsilon_pixel = config.word(key).has_value();
  // "pixel" is resolved against the camera once the scene is loaded (resolve_accelerator).
  plan.accelerator.hmq.epsilon = plan.accel_goal.hmq_epsilon_pixel ? 0.0 : config.real(key);
}
void read_memory_budget(const Config& config, std::string_view key, RenderPlan& plan) {
  const std::string& budget = config.text(key);
  try {
    plan.memory.budget = budget == "none" ? std::nullopt : std::optional<MemoryBudget>(parse_memory_budget(budget));
  } catch (const std::invalid_argument& error) {
    throw ConfigError(fmt::format("{}: {}", key, error.what()));
  }
}
void read_backing(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.memory.file_backing = config.text(key) == "file";
}
void read_io(const Config& config, std::string_view key, RenderPlan& plan) { plan.memory.io = io_preset(config.text(key)); }
void read_cache(const Config& config, std::string_view key, RenderPlan& plan) {
  const std::string& cache = config.text(key);
  plan.memory.cache = cache == "none"     ? std::nullopt
                      : cache == "custom" ? std::optional<CacheGeometry>(CacheGeometry{"custom", 64, 0, 0})
                                          : std::optional<CacheGeometry>(cache_preset(cache));
}
template <std::size_t CacheGeometry::*Member>
void read_cache_size(const Config& config, std::string_view key, RenderPlan& plan) {
  if (plan.memory.cache && config.has(key)) (*plan.memory.cache).*Member = static_cast<std::size_t>(config.integer(key));
}
void read_proxy_accel(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.proxy.accelerator.type = config.text(key);  // the main accelerator's options otherwise (copied in plan_render)
}
void read_buffer_bytes(const Config& config, std::string_view key, RenderPlan& plan) {
  if (!config.has(key)) return;
  plan.reorder.buffer_rays =
      std::max<std::size_t>(1, static_cast<std::size_t>(config.integer(key)) / ZSortStage::kBytesPerBufferedRay);
}
void read_sort(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.reorder.sort = config.text(key) == "radix" ? SortAlgorithm::radix : SortAlgorithm::parallel;
}
void read_stages(const Config& config, std::string_view key, RenderPlan& plan) { plan.stages = config.text_list(key); }

const PlanKey kPlanKeys[] = {
    {"scene.source", text<&P::scene, &SceneRequest::source>},
    {"scene.subdivide", integer<&P::scene, &SceneRequest::subdivide>},
    {"camera.position", optional_vector3<&P::camera, &CameraOverride::position>},
    {"camera.look_at", optional_vector3<&P::camera, &CameraOverride::look_at>},
    {"camera.up", optional_vector3<&P::camera, &CameraOverride::up>},
    {"camera.fov", optional_float<&P::camera, &CameraOverride::vertical_fov_degrees>},
    {"render.width", integer<&P::image, &ImageSpec::width>},
    {"render.height", integer<&P::image, &ImageSpec::height>},
    {"render.spp", integer<&P::image, &ImageSpec::samples_per_pixel>},
    {"render.seed", integer<&P::image, &ImageSpec::seed>},
    {"render.max_depth", integer<&P::rules, &PathRules::max_depth>},
    {"render.russian_roulette_depth", integer<&P::rules, &PathRules::russian_roulette_depth>},
    {"render.threads", read_threads},
    {"render.batch_size", integer<&P::pipeline, &PipelineOptions::batch_size>},
    {"render.rays_in_flight", optional_size<&P::pipeline, &PipelineOptions::rays_in_flight>},
    {"render.film", read_film},
    {"render.pixel_order", choice<parse_pixel_order, &P::pixel_order>},
    {"accel.type", read_accel_type},
    {"accel.memory_budget", text<&P::accel_goal, &AccelGoal::memory_budget>},
    {"accel.max_error", read_max_error},
    {"accel.embree.mode", choice<parse_embree_mode, &P::accelerator, &A::embree, &EmbreeOptions::mode>},
    {"accel.embree.queries", choice<parse_embree_queries, &P::accelerator, &A::embree, &EmbreeOptions::queries>},
    {"accel.bvh.leaf_size", integer<&P::accelerator, &A::bvh, &BvhOptions::max_leaf_size>},
    {"accel.bvh.layout", choice<parse_node_layout, &P::accelerator, &A::bvh, &BvhOptions::layout>},
    {"accel.bvh.triangle_order", choice<parse_triangle_order, &P::accelerator, &A::bvh, &BvhOptions::triangle_order>},
    {"accel.bvh.bins", read_bins},
    {"accel.bvh.width", integer<&P::accelerator, &A::bvh, &BvhOptions::width>},
    {"accel.grid.density", real<&P::accelerator, &A::grid, &HashedGridOptions::density>},
    {"accel.grid.max_cells", integer<&P::accelerator, &A::grid, &HashedGridOptions::max_cells>},
    {"accel.mlgrid.density", real<&P::accelerator, &A::mlgrid, &HashedGridOptions::density>},
    {"accel.mlgrid.max_cells", integer<&P::accelerator, &A::mlgrid, &HashedGridOptions::max_cells>},
    {"accel.mlgrid.macrocell_factor", integer<&P::accelerator, &A::mlgrid, &HashedGridOptions::macrocell_factor>},
    {"accel.arraygrid.density", real<&P::accelerator, &A::arraygrid, &ArrayGridOptions::density>},
    {"accel.arraygrid.refine_items", integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::refine_items>},
    {"accel.arraygrid.max_depth", integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::max_depth>},
    {"accel.arraygrid.max_cells", integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::max_cells>},
    {"accel.arraygrid.max_entries", integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::max_entries>},
    {"accel.raystrips.submesh_triangles",
     integer<&P::accelerator, &A::raystrips, &RayStripsOptions::submesh_triangles>},
    {"accel.raystrips.stripifier", choice<parse_stripifier, &P::accelerator, &A::raystrips, &RayStripsOptions::stripifier>},
    {"accel.raystrips.strips_per_leaf", integer<&P::accelerator, &A::raystrips, &RayStripsOptions::strips_per_leaf>},
    {"accel.raystrips.run_triangles", integer<&P::accelerator, &A::raystrips, &RayStripsOptions::run_triangles>},
    {"accel.raystrips.packets", boolean<&P::accelerator, &A::raystrips, &RayStripsOptions::packets>},
    {"accel.raystrips.width", integer<&P::accelerator, &A::raystrips, &RayStripsOptions::width>},
    {"accel.raystrips.packet_min_active",
     integer<&P::accelerator, &A::raystrips, &RayStripsOptions::packet_min_active>},
    {"accel.hmq.bits", integer<&P::accelerator, &A::hmq, &HmqOptions::bits>},
    {"accel.hmq.epsilon", read_hmq_epsilon},
    {"accel.hmq.leaf_size", integer<&P::accelerator, &A::hmq, &HmqOptions::leaf_size>},
    {"accel.hmq.top_fraction", real<&P::accelerator, &A::hmq, &HmqOptions::top_fraction>},
    {"accel.hmq.width", integer<&P::accelerator, &A::hmq, &HmqOptions::width>},
    {"build.chunk_triangles", integer<&P::accelerator, &A::chunk_triangles>},
    {"memory.budget", read_memory_budget},
    {"memory.page_bytes", integer<&P::memory, &MemoryPlan::page_bytes>},
    {"memory.backing", read_backing},
    {"memory.io", read_io},
    {"memory.cache", read_cache},  // before the three below, which adjust its geometry
    {"memory.cache_line_bytes", read_cache_size<&CacheGeometry::line_bytes>},
    {"memory.cache_bytes", read_cache_size<&CacheGeometry::capacity_bytes>},
    {"memory.cache_ways", read_cache_size<&CacheGeometry::ways>},
    {"proxy.share", real<&P::proxy, &ProxyOptions::share>},
    {"proxy.method", choice<parse_proxy_method, &P::proxy, &ProxyOptions::method>},
    {"proxy.accel", read_proxy_accel},
    {"reorder.heuristic", choice<parse_reorder_heuristic, &P::reorder, &ZSortOptions::heuristic>},
    {"reorder.curve", choice<parse_curve_kind, &P::reorder, &ZSortOptions::curve>},
    {"reorder.buffer_rays", integer<&P::reorder, &ZSortOptions::buffer_rays>},
    {"reorder.buffer_bytes", read_buffer_bytes},  // after buffer_rays, which it overrides
    {"reorder.sort", read_sort},
    {"pipeline.stages", read_stages},
    {"pipeline.mode", choice<parse_pipeline_mode, &P::pipeline, &PipelineOptions::mode>},
    {"pipeline.tile", integer<&P::pipeline, &PipelineOptions::tile_side>},
};

}  // namespace

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
}

void check_memory_plan(const Config& config, const MemoryPlan& plan) {
  if (!std::has_single_bit(plan.page_bytes)) {
    throw ConfigError(fmt::format("memory.page_bytes = {} is not a power of two", plan.page_bytes));
  }
  if (plan.file_backing && !plan.budget) {
    throw ConfigError("memory.backing = file pages a world file under memory.budget: set one (for example 20%)");
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

std::span<const PlanKey> plan_keys() { return kPlanKeys; }

void read_plan_keys(const Config& config, RenderPlan& plan, std::string_view prefix) {
  for (const PlanKey& row : kPlanKeys) {
    if (row.key.starts_with(prefix)) row.read(config, row.key, plan);
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

}  // namespace wavetrace
