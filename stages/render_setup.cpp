// Config to plan, plan to stages, stages to image.
#include "stages/render_setup.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/info.h>

#include "memory/process_memory.hpp"
#include "scene/builtin_scenes.hpp"
#include "stages/approx_hit.hpp"
#include "stages/megakernel.hpp"
#include "stages/repack.hpp"
#include "stages/shade.hpp"
#include "stages/spawn.hpp"
#include "stages/trace.hpp"

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

int worker_count(const PipelineOptions& options) {
  return options.threads > 0 ? options.threads : tbb::info::default_concurrency();
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

AcceleratorOptions accelerator_options(const Config& config) {
  AcceleratorOptions options;
  options.type = config.text("accel.type");
  options.embree.mode = parse_embree_mode(config.text("accel.embree.mode"));
  options.embree.queries = parse_embree_queries(config.text("accel.embree.queries"));
  options.embree.threads = static_cast<int>(config.integer("render.threads"));
  options.bvh.max_leaf_size = static_cast<std::uint32_t>(config.integer("accel.bvh.leaf_size"));
  options.bvh.layout = parse_node_layout(config.text("accel.bvh.layout"));
  options.bvh.triangle_order = parse_triangle_order(config.text("accel.bvh.triangle_order"));
  options.bvh.bins = static_cast<std::uint32_t>(config.integer("accel.bvh.bins"));
  options.bvh.width = static_cast<std::uint32_t>(config.integer("accel.bvh.width"));
  options.grid.density = config.real("accel.grid.density");
  options.grid.max_cells = static_cast<std::size_t>(config.integer("accel.grid.max_cells"));
  options.arraygrid.density = config.real("accel.arraygrid.density");
  options.arraygrid.refine_items = static_cast<std::uint32_t>(config.integer("accel.arraygrid.refine_items"));
  options.arraygrid.max_depth = static_cast<std::uint32_t>(config.integer("accel.arraygrid.max_depth"));
  options.arraygrid.max_cells = static_cast<std::size_t>(config.integer("accel.arraygrid.max_cells"));
  options.arraygrid.max_entries = static_cast<std::size_t>(config.integer("accel.arraygrid.max_entries"));
  options.raystrips.submesh_triangles = static_cast<std::uint32_t>(config.integer("accel.raystrips.submesh_triangles"));
  options.raystrips.stripifier = parse_stripifier(config.text("accel.raystrips.stripifier"));
  options.raystrips.strips_per_leaf = static_cast<std::uint32_t>(config.integer("accel.raystrips.strips_per_leaf"));
  options.raystrips.run_triangles = static_cast<std::uint32_t>(config.integer("accel.raystrips.run_triangles"));
  options.raystrips.packets = config.boolean("accel.raystrips.packets");
  options.raystrips.packet_min_active = static_cast<std::uint32_t>(config.integer("accel.raystrips.packet_min_active"));
  options.raystrips.bins = options.bvh.bins;
  options.raystrips.width = static_cast<std::uint32_t>(config.integer("accel.raystrips.width"));
  options.hmq.bits = static_cast<std::uint32_t>(config.integer("accel.hmq.bits"));
  // "pixel" is resolved against the camera once the scene is loaded (resolve_accelerator).
  options.hmq.epsilon = config.word("accel.hmq.epsilon") ? 0.0 : config.real("accel.hmq.epsilon");
  options.hmq.leaf_size = static_cast<std::uint32_t>(config.integer("accel.hmq.leaf_size"));
  options.hmq.top_fraction = config.real("accel.hmq.top_fraction");
  options.hmq.width = static_cast<std::uint32_t>(config.integer("accel.hmq.width"));
  options.hmq.bins = options.bvh.bins;
  // epsilon chooses the bits: both given (even bits = 16, the default) is a conflict.
  if ((config.given("accel.hmq.bits") && config.given("accel.hmq.epsilon")) ||
      (options.hmq.epsilon > 0.0 && options.hmq.bits != HmqOptions{}.bits)) {
    throw ConfigError(fmt::format("accel.hmq.bits = {} and accel.hmq.epsilon = {}: set one of them (epsilon "
                                  "chooses the bits)",
                                  options.hmq.bits, options.hmq.epsilon));
  }
  options.chunk_triangles = static_cast<std::size_t>(config.integer("build.chunk_triangles"));
  options.mlgrid.density = config.real("accel.mlgrid.density");
  options.mlgrid.max_cells = static_cast<std::size_t>(config.integer("accel.mlgrid.max_cells"));
  options.mlgrid.macrocell_factor = static_cast<std::uint32_t>(config.integer("accel.mlgrid.macrocell_factor"));
  if (options.bvh.width != 2 && options.bvh.width != 8) {
    throw ConfigError(fmt::format("accel.bvh.width = {}: must be 2 or 8", options.bvh.width));
  }
  if (options.raystrips.width != 2 && options.raystrips.width != 8) {
    throw ConfigError(fmt::format("accel.raystrips.width = {}: must be 2 or 8", options.raystrips.width));
  }
  if (options.hmq.width != 2 && options.hmq.width != 8) {
    throw ConfigError(fmt::format("accel.hmq.width = {}: must be 2 or 8", options.hmq.width));
  }
  // A top share set for the wide layout, which has no float top, is refused, not ignored.
  if (options.hmq.width == 8 &&
      (config.given("accel.hmq.top_fraction") || options.hmq.top_fraction != HmqOptions{}.top_fraction)) {
    throw ConfigError(fmt::format("accel.hmq.top_fraction = {} applies to the binary layout (width 2): width 8 "
                                  "quantizes every node",
                                  options.hmq.top_fraction));
  }
  return options;
}

std::unique_ptr<Accelerator> build_world_accelerator(const Scene& scene, const AcceleratorOptions& options) {
  if (scene.streamed()) return make_world_accelerator(*scene.stream, nullptr, options);
  const MeshTriangleSource source(scene.mesh);
  return make_world_accelerator(source, &scene.mesh, options);
}

void check_scene_fits(const RenderPlan& plan) {
  const std::string& source = plan.scene.source;
  // accel.type = auto chooses by its own budget.
  if (!is_builtin_scene(source) || plan.scene.subdivide > 0 || plan.accel_goal.automatic) return;
  const std::optional<std::size_t> requested = requested_triangle_count(source);
  if (!requested) return;
  const double triangles = double(*requested);
  const std::size_t available = available_memory_bytes();
  if (available == 0) return;
  // Measured on builtin:room (README, "Memory at scale"): the finished structure, the mesh
  // when it is built whole (positions, indices, a material per triangle), and the build's
  // temporaries, bounded by a chunk where the type builds in chunks.
  const double structure = estimated_bytes_per_triangle(plan.accelerator);
  const double mesh = plan.scene.streamed ? 0.0 : kWholeMeshBytesPerTriangle;
  const double build_triangles = builds_in_chunks(plan.accelerator.type)
                                     ? std::min(triangles, double(plan.accelerator.chunk_triangles))
                                     : triangles;
  const double needed =
      triangles * (structure + mesh) + build_triangles * estimated_build_bytes_per_triangle(plan.accelerator.type);
  if (needed > double(available)) {
    throw SceneError(fmt::format(
        "{}: about {:.1f} GB needed to build '{}' ({:.0f} bytes/triangle{} plus build temporaries) but {:.1f} GB "
        "of memory is available; try fewer triangles or a more compact accelerator (hmq)",
        source, needed * 1e-9, plan.accelerator.type, structure, mesh > 0.0 ? " and the whole mesh" : "",
        double(available) * 1e-9));
  }
}

SceneForWorld load_scene_for_world(const RenderPlan& plan, bool keep_mesh) {
  SceneRequest request = plan.scene;
  request.streamed = (plan.accel_goal.automatic || holds_own_geometry(plan.accelerator.type)) && !keep_mesh;
  RenderPlan checked = plan;
  checked.scene = request;
  check_scene_fits(checked);
  Scene scene = load_scene(request);
  const Camera camera = resolve_camera(plan.camera, scene);
  const MeshTriangleSource whole(scene.mesh);
  const TriangleSource& triangles = scene.streamed() ? *scene.stream : static_cast<const TriangleSource&>(whole);
  ResolvedAccelerator resolved =
      resolve_accelerator(plan.accelerator, plan.accel_goal, triangles, camera, plan.image, scene.streamed());
  if (scene.streamed() && !holds_own_geometry(resolved.options.type)) {
    request.streamed = false;
    scene = load_scene(request);
  }
  return {std::move(scene), camera, std::move(resolved)};
}

RenderPlan plan_render(const Config& config) {
  RenderPlan plan;
  plan.scene.source = config.text("scene.source");
  plan.scene.subdivide = static_cast<int>(config.integer("scene.subdivide"));
  if (config.has("camera.position")) plan.camera.position = config.vector3("camera.position");
  if (config.has("camera.look_at")) plan.camera.look_at = config.vector3("camera.look_at");
  if (config.has("camera.up")) plan.camera.up = config.vector3("camera.up");
  if (config.has("camera.fov")) plan.camera.vertical_fov_degrees = static_cast<float>(config.real("camera.fov"));

  plan.image.width = static_cast<std::uint32_t>(config.integer("render.width"));
  plan.image.height = static_cast<std::uint32_t>(config.integer("render.height"));
  plan.image.samples_per_pixel = static_cast<std::uint32_t>(config.integer("render.spp"));
  if (std::uint64_t(plan.image.width) * plan.image.height * plan.image.samples_per_pixel > (std::uint64_t{1} << 40)) {
    throw ConfigError("render: width x height x spp is over 2^40 rays");
  }
  const std::uint64_t seed = static_cast<std::uint64_t>(config.integer("render.seed"));
  if ((seed + 1) * plan.image.samples_per_pixel > std::numeric_limits<std::uint32_t>::max()) {
    throw ConfigError(fmt::format("render.seed = {} with render.spp = {}: the sample numbers, up to (seed + 1) x spp, "
                                  "must stay under 2^32",
                                  seed, plan.image.samples_per_pixel));
  }
  plan.image.seed = static_cast<std::uint32_t>(seed);
  plan.pixel_order = parse_pixel_order(config.text("render.pixel_order"));
  plan.film_per_thread = config.text("render.film") == "per_thread";
  plan.rules.max_depth = static_cast<std::uint32_t>(config.integer("render.max_depth"));
  plan.rules.russian_roulette_depth = static_cast<std::uint32_t>(config.integer("render.russian_roulette_depth"));
  plan.pipeline.batch_size = static_cast<std::size_t>(config.integer("render.batch_size"));
  plan.pipeline.threads = static_cast<int>(config.integer("render.threads"));
  plan.pipeline.mode = parse_pipeline_mode(config.text("pipeline.mode"));
  plan.pipeline.tile_side = static_cast<std::uint32_t>(config.integer("pipeline.tile"));
  plan.memory = plan_memory(config);

  plan.accelerator = accelerator_options(config);
  plan.accel_goal = accel_goal(config);

  plan.proxy.share = config.real("proxy.share");
  plan.proxy.method = parse_proxy_method(config.text("proxy.method"));
  plan.proxy.accelerator = plan.accelerator;
  plan.proxy.accelerator.type = config.text("proxy.accel");
  plan.reorder.heuristic = parse_reorder_heuristic(config.text("reorder.heuristic"));
  plan.reorder.curve = parse_curve_kind(config.text("reorder.curve"));
  plan.reorder.buffer_rays = static_cast<std::size_t>(config.integer("reorder.buffer_rays"));
  if (config.given("reorder.buffer_rays") && config.has("reorder.buffer_bytes")) {
    throw ConfigError("reorder.buffer_rays and reorder.buffer_bytes both size the reorder buffer: set one of them");
  }
  if (config.has("reorder.buffer_bytes")) {
    plan.reorder.buffer_rays = std::max<std::size_t>(
        1, static_cast<std::size_t>(config.integer("reorder.buffer_bytes")) / ZSortStage::kBytesPerBufferedRay);
  }
  plan.reorder.sort = config.text("reorder.sort") == "radix" ? SortAlgorithm::radix : SortAlgorithm::parallel;

  plan.stages = config.text_list("pipeline.stages");
  if (plan.stages == std::vector<std::string>{"auto"}) plan.stages = stages_for(plan.reorder.heuristic);
  if (std::count(plan.stages.begin(), plan.stages.end(), "auto") > 0) {
    throw ConfigError("pipeline.stages: 'auto' stands alone");
  }
  check_stage_order(plan.stages, plan.reorder.heuristic);
  if (config.has("render.rays_in_flight")) {
    plan.pipeline.rays_in_flight = static_cast<std::size_t>(config.integer("render.rays_in_flight"));
  } else if (std::find(plan.stages.begin(), plan.stages.end(), "zsort") != plan.stages.end()) {
    plan.pipeline.rays_in_flight = plan.reorder.buffer_rays;  // so that the buffer can fill
  } else {
    // Without a buffer to fill, rays in flight only keep the workers busy; more would cost
    // memory (and first-touch page faults) for nothing.
    plan.pipeline.rays_in_flight = 4 * std::size_t(worker_count(plan.pipeline)) * plan.pipeline.batch_size;
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

std::unique_ptr<Proxy> build_proxy(const RenderPlan& plan, const Scene& scene, const Accelerator& accelerator) {
  if (!plan.needs_proxy()) return nullptr;
  return std::make_unique<Proxy>(scene.mesh, plan.proxy, accelerator);
}

Camera resolve_camera(const CameraOverride& override, const Scene& scene) {
  Camera camera = scene.camera.value_or(frame_bounds(scene.bounds));
  if (override.position) camera.position = *override.position;
  if (override.look_at) camera.look_at = *override.look_at;
  if (override.up) camera.up = *override.up;
  if (override.vertical_fov_degrees) camera.vertical_fov_degrees = *override.vertical_fov_degrees;
  validate_camera(camera);
  return camera;
}

StageChain::StageChain(const RenderPlan& plan, const World& world, Film& film, const MemoryObservers* observers) {
  const PathRules& rules = plan.rules;
  for (const std::string& name : plan.stages) {
    if (name == "generate") continue;
    if (name == "approx_hit") {
      if (world.proxy == nullptr) throw std::logic_error("approx_hit needs the world's proxy");
      owned_.push_back(std::make_unique<ApproxHitStage>(*world.proxy, film, world.scene.background, &hit_rates_, observers));
    }
    if (name == "zsort") {
      auto zsort = std::make_unique<ZSortStage>(plan.reorder, world.scene.bounds);
      zsort_ = zsort.get();
      owned_.push_back(std::move(zsort));
    }
    if (name == "repack") owned_.push_back(std::make_unique<RepackStage>(plan.pipeline.batch_size / 2));
    if (name == "trace") {
      owned_.push_back(std::make_unique<TraceStage>(world.accelerator, world.scene.material_runs,
                                                    TraceInstruments{&hit_rates_, observers, &trace_times_}));
    }
    if (name == "shade") owned_.push_back(std::make_unique<ShadeStage>(world, film, rules));
    if (name == "spawn") {
      owned_.push_back(std::make_unique<SpawnStage>(world, rules));
      loops_ = true;
    }
  }
}

std::vector<const Stage*> StageChain::stages() const {
  std::vector<const Stage*> stages;
  for (const auto& stage : owned_) stages.push_back(stage.get());
  return stages;
}

RenderOutput render_image(const RenderPlan& plan, const World& world, const Camera& camera,
                          const std::function<void(const Progress&)>& on_progress) {
  const int workers = worker_count(plan.pipeline);
  Film film(plan.image.width, plan.image.height, plan.film_per_thread ? std::uint32_t(workers) : 0);
  GenerateStage generate(camera, plan.image, plan.pixel_order);
  std::optional<MemoryObservation> observation;
  RenderOutput output;
  if (plan.memory.enabled()) {
    if (world.accelerator.probed()) {
      std::vector<std::span<const std::byte>> spans = world.accelerator.memory_spans();
      if (world.proxy != nullptr && plan.needs_proxy()) {
        for (const auto& span : world.proxy->accelerator().memory_spans()) spans.push_back(span);
      }
      observation.emplace(plan.memory, std::move(spans), workers, plan.memory.file_backing ? world.pager : nullptr);
    } else {
      output.memory_unobserved = fmt::format("accelerator '{}' cannot report its memory reads: no pager or cache counters",
                                             world.accelerator.name());
    }
  }
  if (plan.pipeline.mode == PipelineMode::megakernel) {
    // The control experiment runs without the trace stage's per-run clocks and counters
    // (and plan_render refused [memory] observation for it).
    const TraceStage trace(world.accelerator, world.scene.material_runs);
    const ShadeStage shade(world, film, plan.rules);
    const SpawnStage spawn(world, plan.rules);
    output.run = run_megakernel(generate, trace, shade, &spawn, {plan.pipeline.threads, plan.pipeline.tile_side},
                                on_progress);
  } else {
    const StageChain chain(plan, world, film, observation ? &observation->observers() : nullptr);
    Pipeline pipeline(generate, chain.stages(), chain.loops(), plan.pipeline);
    output.run = pipeline.run(on_progress);
    if (observation) observation->report(output.run.stages);
    if (chain.zsort() != nullptr) output.sort_seconds = chain.zsort()->sort_seconds();
    output.closest_mrays_per_s = chain.trace_times().closest_mrays_per_s();
    output.any_mrays_per_s = chain.trace_times().any_mrays_per_s();
    output.hit_rates = chain.hit_rates().snapshot();
  }
  output.image = film.resolve(plan.image.samples_per_pixel);
  output.rejected_contributions = film.rejected_contributions();
  return output;
}

}  // namespace wavetrace
