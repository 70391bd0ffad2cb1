// The one key table: every configuration key with its type, default, valid range, help text
// and the plan field it sets. Adding an option means adding one row here; the option
// structs' own defaults must equal the row's (ConfigKeys.OptionStructDefaultsEqualTheTable),
// and docs/configuration.md is generated from it (`wavetrace keys --markdown`).
#include <algorithm>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>

#include "wavetrace/pipeline/pipeline.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/setup/render_plan.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"

namespace wavetrace {
namespace {

// The plan field a path of member pointers names: field<&RenderPlan::image, &ImageSpec::width>.
template <auto... Path>
auto& field(RenderPlan& plan) {
  return (plan.*....*Path);
}
template <auto... Path>
const auto& field(const RenderPlan& plan) {
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


// A built accelerator's setting as the world file records it (ConfigKey::record).
using Recorded = std::optional<ConfigValue>;
template <auto... Path>
Recorded recorded_integer(const RenderPlan& plan) {
  return std::int64_t(field<Path...>(plan));
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
// A parser's std::invalid_argument becomes the ConfigError every bad value raises; the key is
// named in front unless the parser's own message names it (name_key = false).
template <class Parse>
auto parsed_as_config(std::string_view key, bool name_key, Parse&& parse) {
  try {
    return parse();
  } catch (const std::invalid_argument& error) {
    throw ConfigError(name_key ? fmt::format("{}: {}", key, error.what()) : std::string(error.what()));
  }
}
void read_memory_budget(const Config& config, std::string_view key, RenderPlan& plan) {
  const std::string& budget = config.text(key);
  plan.memory.budget = parsed_as_config(key, true, [&] {
    return budget == "none" ? std::nullopt : std::optional<MemoryBudget>(parse_memory_budget(budget));
  });
}
// accel.isa kept as written ("auto" is resolved when an accelerator is made), once checked
// against this build and CPU; the parser's message names accel.isa, or WAVETRACE_ISA where that chose.
void read_kernel_isa(const Config& config, std::string_view key, RenderPlan& plan) {
  const std::string& isa = config.text(key);
  parsed_as_config(key, false, [&] { return parse_kernel_isa(isa); });
  plan.accelerator.isa = isa;
}
void read_backing(const Config& config, std::string_view key, RenderPlan& plan) {
  plan.memory.file_backing = config.text(key) == "file";
  plan.memory.copy_world = config.text(key) == "copy";
}
void read_page_mapping(const Config& config, std::string_view key, RenderPlan& plan) {
  const std::string& mapping = config.text(key);
  plan.memory.page_mapping = mapping == "userfaultfd" ? PageMapping::userfaultfd
                             : mapping == "memfd"     ? PageMapping::memfd
                                                      : PageMapping::automatic;
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
void read_proxy_share(const Config& config, std::string_view key, RenderPlan& plan) {
  // "auto" (no number): resolved from the memory plan in plan_render.
  plan.proxy.share_by_holding = config.word(key).has_value();
  if (!plan.proxy.share_by_holding) plan.proxy.share = config.real(key);
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

// The registry's types, then auto.
std::vector<std::string> accel_type_choices() {
  std::vector<std::string> choices = accelerator_names();
  choices.push_back("auto");
  return choices;
}

}  // namespace

const std::vector<std::string>& config_sections() {
  static const std::vector<std::string> sections = {"scene",  "camera",  "render", "photon",   "accel",     "build",
                                                    "proxy",  "reorder", "memory", "pipeline", "distribute"};
  return sections;
}

// Rows in an order where a row may read what earlier rows set (memory.cache before the
// sizes that adjust its geometry; reorder.buffer_bytes after buffer_rays, which it overrides).
const std::vector<ConfigKey>& config_schema() {
  using T = ConfigType;
  static const std::vector<ConfigKey> schema = {
      {"scene.source", T::text, std::string("builtin:default"), 0, 0, {},
       "mesh file (.off .ply .obj .stl), scene file (.toml) or builtin:NAME[:TRIANGLES]",
       text<&P::scene, &SceneRequest::source>},
      {"scene.subdivide", T::integer, std::int64_t{0}, 0, 6, {}, "levels of Loop subdivision after loading (the new triangles numbered along the Z-curve of their centroids)",
       integer<&P::scene, &SceneRequest::subdivide>},

      {"camera.position", T::vector3, std::nullopt, 0, 0, {}, "eye point (default: the scene's or framed)",
       optional_vector3<&P::camera, &CameraOverride::position>},
      {"camera.look_at", T::vector3, std::nullopt, 0, 0, {}, "point looked at",
       optional_vector3<&P::camera, &CameraOverride::look_at>},
      {"camera.up", T::vector3, std::nullopt, 0, 0, {}, "up direction (default: the scene's, or +y)",
       optional_vector3<&P::camera, &CameraOverride::up>},
      {"camera.fov", T::real, std::nullopt, 1, 179, {}, "vertical field of view in degrees",
       optional_float<&P::camera, &CameraOverride::vertical_fov_degrees>},

      {"render.width", T::integer, std::int64_t{640}, 1, 16384, {}, "image width in pixels",
       integer<&P::image, &ImageSpec::width>},
      {"render.height", T::integer, std::int64_t{480}, 1, 16384, {}, "image height in pixels",
       integer<&P::image, &ImageSpec::height>},
      {"render.spp", T::integer, std::int64_t{8}, 1, 65536, {}, "samples per pixel",
       integer<&P::image, &ImageSpec::samples_per_pixel>},
      {"render.seed", T::integer, std::int64_t{0}, 0, 1 << 20, {},
       "which samples are drawn: seed k draws samples k*spp .. (k+1)*spp - 1 of each pixel (another seed, "
       "independent noise)",
       integer<&P::image, &ImageSpec::seed>},
      {"render.max_depth", T::integer, std::int64_t{5}, 0, 64, {},
       "most bounces of a path (0: direct light only)",
       integer<&P::rules, &PathRules::max_depth>},
      {"render.russian_roulette_depth", T::integer, std::int64_t{3}, 0, 64, {},
       "bounce depth from which Russian roulette may end a path",
       integer<&P::rules, &PathRules::russian_roulette_depth>},
      {"render.threads", T::integer, std::int64_t{0}, 0, 1024, {}, "worker threads (0: all cores)",
       read_threads},
      {"render.batch_size", T::integer, std::int64_t{kPipelineBatchSize}, 16, 1 << 20, {},
       "rays per batch (1024: a batch and its hits, ~100 KB, stay in L2 between stages)",
       integer<&P::pipeline, &PipelineOptions::batch_size>},
      {"render.rays_in_flight", T::integer, std::nullopt, 1024, std::int64_t{1} << 30, {},
       "most rays alive in memory at once (bounds memory; camera rays are emitted while there is room for what "
       "each may become: 2 rays with spawn, photon.gather_rays + 1 with photon mapping); default: "
       "reorder.buffer_rays with zsort in the chain (with reorder.buffer = disk, times what a camera ray may "
       "become, so that the in-core part fills), else 4 batches of camera rays per worker and what they become",
       optional_size<&P::pipeline, &PipelineOptions::rays_in_flight>},
      {"render.film", T::text, std::string("shared"), 0, 0, {"shared", "per_thread"},
       "shared: one film, atomic adds; per_thread: a film per worker, summed at the end (same image)",
       read_film},
      {"render.pixel_order", T::text, std::string("zcurve"), 0, 0, {"scanline", "zcurve"},
       "order in which camera rays are generated: zcurve (the reordering paper's; each batch a compact block of "
       "pixels) or scanline (each batch a strip of rows); the image is the same",
       choice<parse_pixel_order, &P::pixel_order>},
      {"render.integrator", T::text, std::string("path"), 0, 0, {"path", "photon"},
       "path: path tracing; photon: a photon pass, then camera rays with light samples, the caustic map and final "
       "gathering from the global map (photon.*)",
       choice<parse_integrator, &P::integrator>},

      {"photon.count", T::integer, std::int64_t{1000000}, 1, std::int64_t{4294967295}, {},
       "photons emitted from the lights (render.integrator = photon)",
       integer<&P::photon, &PhotonOptions::count>},
      {"photon.k", T::integer, std::int64_t{100}, 1, 1024, {}, "photons each irradiance estimate gathers",
       integer<&P::photon, &PhotonOptions::k>},
      {"photon.radius", T::real, 0.0, 0.0, 1e30, {},
       "the farthest an irradiance estimate reaches, in scene units (0: 0.25% of the scene's diagonal)",
       real<&P::photon, &PhotonOptions::radius>},
      {"photon.gather_rays", T::integer, std::int64_t{10}, 1, 128, {},
       "final-gathering rays from each diffuse surface a camera path meets",
       integer<&P::photon, &PhotonOptions::gather_rays>},
      {"photon.precompute", T::integer, std::int64_t{0}, 0, 1024, {},
       "precompute the global map's irradiance at every Nth photon and let gathering rays read the nearest "
       "(Christensen 1999); 0: a full k-nearest estimate at every gathering hit",
       integer<&P::photon, &PhotonOptions::precompute>},

      {"accel.type", T::text, std::string("embree"), 0, 0,
       accel_type_choices(),
       "main accelerator (auto: the fastest that fits accel.memory_budget and meets accel.max_error)",
       read_accel_type},
      {"accel.memory_budget", T::text, std::string("available"), 0, 0, {},
       "what accel.type = auto may spend on the whole process (structure, mesh, build): bytes ('8GB', '512MiB'), a "
       "share of the memory available now ('50%'), or 'available' (what is available now, less 10%); not "
       "memory.budget, the page pool",
       text<&P::accel_goal, &AccelGoal::memory_budget>},
      {"accel.max_error", T::real, std::string("pixel"), 0.0, 1e30, {"pixel"},
       "largest hit-point error accel.type = auto may accept, in scene units (0: exact methods only), or pixel: half "
       "a pixel's footprint at the nearest surface in view",
       read_max_error},
      {"accel.embree.mode", T::text, std::string("default"), 0, 0, {"default", "compact", "robust"},
       "Embree scene flags",
       choice<parse_embree_mode, &P::accelerator, &A::embree, &EmbreeOptions::mode>,
       [](const RenderPlan& plan) -> Recorded { return to_string(plan.accelerator.embree.mode); }},
      {"accel.embree.queries", T::text, std::string("stream"), 0, 0, {"single", "stream"},
       "rtcIntersect1 per ray, or a batch range through rtcIntersectNp (camera rays flagged coherent)",
       choice<parse_embree_queries, &P::accelerator, &A::embree, &EmbreeOptions::queries>},
      {"accel.embree.isa", T::text, std::string("native"), 0, 0, {"native", "avx2", "sse4.2"},
       "Embree's kernels: the best the CPU has (AVX-512 where present), or forced down, for a comparison "
       "with walks of that ISA",
       choice<parse_embree_isa, &P::accelerator, &A::embree, &EmbreeOptions::isa>,
       [](const RenderPlan& plan) -> Recorded { return plan.accelerator.embree.isa; }},
      {"accel.isa", T::text, std::string("auto"), 0, 0, {"auto", "avx2", "avx512"},
       "kernels of our walks: auto (AVX-512 where the CPU has it, or what the environment variable WAVETRACE_ISA "
       "names), or one set forced; an error names a set this CPU cannot run (accel.embree.isa is Embree's)",
       read_kernel_isa},
      {"accel.bvh.leaf_size", T::integer, std::int64_t{0}, 0, 16, {},
       "most triangles per BVH leaf; 0: the width's own, 4 for the binary tree and 16 (four blocks of four) for width 8",
       integer<&P::accelerator, &A::bvh, &BvhOptions::max_leaf_size>},
      {"accel.bvh.layout", T::text, std::string("depth_first"), 0, 0, {"depth_first", "breadth_first", "veb"},
       "BVH node order in memory",
       choice<parse_node_layout, &P::accelerator, &A::bvh, &BvhOptions::layout>},
      {"accel.bvh.triangle_order", T::text, std::string("input"), 0, 0, {"input", "morton", "leaf"},
       "the BVH's indexed face set: the mesh's (input), a Morton-sorted copy, or a copy in leaf order",
       choice<parse_triangle_order, &P::accelerator, &A::bvh, &BvhOptions::triangle_order>},
      {"accel.bvh.bins", T::integer, std::int64_t{16}, 2, 64, {}, "SAH bins per axis",
       read_bins},
      {"accel.grid.density", T::real, 32.0, 0.01, 4096.0, {}, "cells per triangle (Woo's heuristic; the paper: 32)",
       real<&P::accelerator, &A::grid, &HashedGridOptions::density>},
      {"accel.grid.max_cells", T::integer, std::int64_t{1} << 30, 1, std::int64_t{1} << 36, {},
       "resolution guard: most cells of the grid (the density is lowered to fit)",
       integer<&P::accelerator, &A::grid, &HashedGridOptions::max_cells>},
      {"accel.grid.bounding_box_lists", T::boolean, false, 0, 0, {},
       "list a triangle in every cell its bounding box overlaps, as the paper does (false: the cells it overlaps)",
       boolean<&P::accelerator, &A::grid, &HashedGridOptions::bounding_box_lists>},
      {"accel.mlgrid.density", T::real, 32.0, 0.01, 4096.0, {}, "cells per triangle of mlgrid's fine grid",
       real<&P::accelerator, &A::mlgrid, &HashedGridOptions::density>},
      {"accel.mlgrid.max_cells", T::integer, std::int64_t{1} << 30, 1, std::int64_t{1} << 36, {},
       "resolution guard of mlgrid",
       integer<&P::accelerator, &A::mlgrid, &HashedGridOptions::max_cells>},
      {"accel.mlgrid.macrocell_factor", T::integer, std::int64_t{6}, 2, 64, {},
       "fine cells per macrocell side, per level (the paper: 6)",
       integer<&P::accelerator, &A::mlgrid, &HashedGridOptions::macrocell_factor>},
      {"accel.mlgrid.bounding_box_lists", T::boolean, false, 0, 0, {},
       "list a triangle in every cell its bounding box overlaps, as the paper does",
       boolean<&P::accelerator, &A::mlgrid, &HashedGridOptions::bounding_box_lists>},
      {"accel.arraygrid.density", T::real, 4.0, 0.01, 4096.0, {}, "cells per triangle of each nested grid (the paper: 4)",
       real<&P::accelerator, &A::arraygrid, &ArrayGridOptions::density>},
      {"accel.arraygrid.refine_items", T::integer, std::int64_t{8}, 2, 1 << 20, {},
       "a cell holding this many triangles is refined",
       integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::refine_items>},
      {"accel.arraygrid.max_depth", T::integer, std::int64_t{2}, 0, 4, {}, "deepest nested grid (root: 0)",
       integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::max_depth>},
      {"accel.arraygrid.max_cells", T::integer, std::int64_t{1} << 28, 1, std::int64_t{1} << 34, {},
       "resolution guard: refinement stops once the grids hold this many cells",
       integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::max_cells>},
      {"accel.arraygrid.max_entries", T::integer, std::int64_t{1} << 28, 1, std::int64_t{1} << 34, {},
       "resolution guard: refinement stops once the triangle lists made hold this many entries",
       integer<&P::accelerator, &A::arraygrid, &ArrayGridOptions::max_entries>},
      {"accel.raystrips.submesh_triangles", T::integer, std::int64_t{0}, 0, 65535, {},
       "sub-mesh threshold: the SAH tree is cut where a subtree holds at most this many triangles, then stripified "
       "(0: 256 under the binary top, 24 under the 8-wide one)",
       integer<&P::accelerator, &A::raystrips, &RayStripsOptions::submesh_triangles>},
      {"accel.raystrips.stripifier", T::text, std::string("longest_of_three"), 0, 0, {"dual_path", "openmesh", "longest_of_three"},
       "longest_of_three: OpenMesh's StripifierT algorithm on flat arrays (its strips, 3x faster); openmesh: StripifierT itself; dual_path: ours (long, spiral strips)",
       choice<parse_stripifier, &P::accelerator, &A::raystrips, &RayStripsOptions::stripifier>},
      {"accel.raystrips.strips_per_leaf", T::integer, std::int64_t{0}, 0, 16, {},
       "most strips per top BVH leaf (1: the paper's one strip per leaf; 0: 1 under the binary top, 4 under the 8-wide one)",
       integer<&P::accelerator, &A::raystrips, &RayStripsOptions::strips_per_leaf>},
      {"accel.raystrips.run_triangles", T::integer, std::int64_t{6}, 2, 64, {},
       "the strip's kd-tree is descended to spans of at most this many triangles, tested together (the paper: 2)",
       integer<&P::accelerator, &A::raystrips, &RayStripsOptions::run_triangles>},
      {"accel.raystrips.packets", T::boolean, true, 0, 0, {}, "camera rays in packets: 2x2 (the paper's) under a binary top, eight (two 2x2 quads) under the 8-wide top",
       boolean<&P::accelerator, &A::raystrips, &RayStripsOptions::packets>},
      {"accel.raystrips.width", T::integer, std::int64_t{2}, 2, 8, {},
       "top over the strips: 2, binary 32-byte nodes; 8, quantized 8-wide nodes",
       integer<&P::accelerator, &A::raystrips, &RayStripsOptions::width>, recorded_integer<&P::accelerator, &A::raystrips, &RayStripsOptions::width>},
      {"accel.raystrips.packet_min_active", T::integer, std::int64_t{2}, 1, 4, {},
       "below this many active rays a 2x2 packet continues as single rays (binary top)",
       integer<&P::accelerator, &A::raystrips, &RayStripsOptions::packet_min_active>},
      {"accel.hmq.bits", T::integer, std::int64_t{16}, 1, 24, {}, "global grid bits per axis (the paper: 16)",
       integer<&P::accelerator, &A::hmq, &HmqOptions::bits>},
      {"accel.hmq.epsilon", T::real, 0.0, 0.0, 1e30, {"pixel"},
       "error bound in scene units instead of bits (0: unset), or pixel: half a pixel's footprint at the nearest "
       "surface in view; the grid is the coarsest that keeps every vertex within it",
       read_hmq_epsilon,
       [](const RenderPlan& plan) -> Recorded {
         return plan.accelerator.hmq.epsilon > 0.0 ? Recorded(plan.accelerator.hmq.epsilon) : std::nullopt;
       }},
      {"accel.hmq.leaf_size", T::integer, std::int64_t{0}, 0, 14, {},
       "most triangles per leaf (the paper: 4, 8, 12); 0: the width's own, 8 for the binary layout and 14 for width 8",
       integer<&P::accelerator, &A::hmq, &HmqOptions::leaf_size>},
      {"accel.hmq.top_fraction", T::real, 0.05, 0.0, 1.0, {},
       "share of the BVH's nodes kept uncompressed at the top (width 2 only)",
       real<&P::accelerator, &A::hmq, &HmqOptions::top_fraction>},
      {"accel.hmq.width", T::integer, std::int64_t{2}, 2, 8, {},
       "2: the paper's binary 4-byte nodes in blocks; 8: 64-byte nodes of 8 children, 8-bit planes, AVX2",
       integer<&P::accelerator, &A::hmq, &HmqOptions::width>, recorded_integer<&P::accelerator, &A::hmq, &HmqOptions::width>},
      {"accel.hmq.layout", T::text, std::string("veb"), 0, 0, {"depth_first", "breadth_first", "veb"},
       "order of the 8-wide nodes in memory and in a world file (width 8 only); veb: cache-oblivious (van Emde Boas)",
       choice<parse_node_layout, &P::accelerator, &A::hmq, &HmqOptions::layout>,
       [](const RenderPlan& plan) -> Recorded {
         return plan.accelerator.hmq.width == 8 ? Recorded(to_string(plan.accelerator.hmq.layout)) : std::nullopt;
       }},
      {"accel.hmq.leaves_beside_nodes", T::boolean, false, 0, 0, {},
       "width 8: each group of sibling nodes followed by its nodes' leaf records in one array, so a paged walk "
       "reads a leaf from its parent's page",
       boolean<&P::accelerator, &A::hmq, &HmqOptions::leaves_beside_nodes>,
       [](const RenderPlan& plan) -> Recorded {
         return plan.accelerator.hmq.width == 8 ? Recorded(plan.accelerator.hmq.leaves_beside_nodes) : std::nullopt;
       }},
      {"accel.tinybvh.layout", T::text, std::string("bvh8"), 0, 0, {"bvh8", "bvh2"},
       "the peer built in with -DWAVETRACE_TINYBVH (bench accel's comparison): BVH8_CPU, its 8-wide AVX2 walk, or "
       "its binary BVH",
       choice<parse_tinybvh_layout, &P::accelerator, &A::tinybvh, &TinyBvhOptions::layout>},
      {"accel.bvh.width", T::integer, std::int64_t{2}, 2, 8, {}, "2: binary 32-byte nodes; 8: AVX2 8-wide nodes",
       integer<&P::accelerator, &A::bvh, &BvhOptions::width>, recorded_integer<&P::accelerator, &A::bvh, &BvhOptions::width>},

      {"build.chunk_triangles", T::integer, std::int64_t{1} << 21, std::int64_t{1024}, std::int64_t{1} << 30, {},
       "scenes of more triangles are built in chunks of at most this many under a top BVH (hmq, raystrips, bvh)",
       integer<&P::accelerator, &A::chunk_triangles>},
      {"build.chunks_at_once", T::integer, std::int64_t{0}, 0, 1024, {},
       "at most this many chunks built at the same time (0: one per thread, as memory allows); 1 holds one chunk's build temporaries, not one per thread",
       integer<&P::accelerator, &A::chunks_at_once>},

      {"memory.budget", T::text, std::string("none"), 0, 0, {},
       "the page pool (simulated, or real with memory.backing = file): none, a share of the world (20%) or a size "
       "(512MiB, 2GB); not accel.memory_budget, which bounds the whole process for auto",
       read_memory_budget},
      {"memory.page_bytes", T::integer, std::int64_t{4} << 20, 4096, std::int64_t{1} << 30, {},
       "page size of the pool in bytes, a power of two (the paper: 4 MiB; real paging of room:64M on this project's "
       "machines is fastest at 256 KiB with memory.page_frames, 64 KiB without: docs/measurements.md)",
       integer<&P::memory, &MemoryPlan::page_bytes>},
      {"memory.backing", T::text, std::string("memory"), 0, 0, {"memory", "copy", "file"},
       "where a world file's pages live: memory (mapped, the OS pages it), copy (read whole into memory on 2 MiB "
       "pages, for walks over gigabytes; mapped where the machine cannot spare the file and 1 GB) or file (real "
       "paging: read on demand with O_DIRECT into a pool of memory.budget, evicted LRU)",
       read_backing},
      {"memory.page_mapping", T::text, std::string("auto"), 0, 0, {"auto", "userfaultfd", "memfd"},
       "real paging (memory.backing = file): how a page read appears at its place. userfaultfd: copied into one "
       "mapping of the whole file (two system calls a read); memfd: a slot of a memfd pool mapped there (four, two of "
       "them changing the process's mappings; at most 30,000 pages resident); auto: userfaultfd where the kernel "
       "allows it, else memfd",
       read_page_mapping},
      {"memory.page_frames", T::boolean, true, 0, 0, {},
       "real paging: walks that can (hmq:width=8's, chunked or not) read resident pages in frames of fixed address, "
       "each page read straight into one and left there until its frame is reused, with no page mapped or unmapped "
       "(pages of 32 KiB or more; other reads go through memory.page_mapping's range, a 64th of the budget); "
       "false: every read through that range",
       boolean<&P::memory, &MemoryPlan::page_frames>},
      {"memory.look_ahead", T::integer, std::int64_t{0}, 0, 64, {},
       "real paging (memory.backing = file): how many of the sorted batches queued for trace a thread of its own "
       "traces ahead (every 4th ray, hits thrown away) so that their pages are read before trace needs them; 0: none "
       "(on a disk that one read at a time already keeps busy it costs time: docs/measurements.md)",
       integer<&P::memory, &MemoryPlan::look_ahead_batches>},
      {"memory.look_ahead_threads", T::integer, std::int64_t{1}, 1, 16, {},
       "real paging with memory.look_ahead: threads reading ahead, each on the next queued batch none has seen, so "
       "that this many reads are in flight beside trace's own (for a disk that serves reads in parallel)",
       integer<&P::memory, &MemoryPlan::look_ahead_threads>},
      {"memory.simulate_beside_file", T::boolean, false, 0, 0, {},
       "real paging: also run the simulated pager over the same reads (a cross-check of the real faults; it costs "
       "render time, a lock per page change)",
       boolean<&P::memory, &MemoryPlan::simulate_beside_file>},
      {"memory.page_trace", T::text, std::string(""), 0, 0, {},
       "real paging: a file to write every page the render touches to, in order (32-bit little-endian page numbers, "
       "replaced at each render), for replacement policies studied offline: bench/page_policies.py",
       text<&P::memory, &MemoryPlan::page_trace>},
      {"memory.io", T::text, std::string("disk"), 0, 0, {"disk", "nvme"},
       "simulated device per fault: disk (the paper's, 101 MB/s, 8 ms) or nvme (3.5 GB/s, 80 us)",
       read_io},
      {"memory.cache", T::text, std::string("none"), 0, 0, {"none", "paper_l2", "l1d", "l2", "custom"},
       "simulated cache per thread: paper_l2 (6 MiB, 24-way), l1d (32 KiB, 8-way), l2 (512 KiB, 8-way)",
       read_cache},
      {"memory.cache_line_bytes", T::integer, std::nullopt, 4, 4096, {}, "cache line bytes (overrides the preset)",
       read_cache_size<&CacheGeometry::line_bytes>},
      {"memory.cache_bytes", T::integer, std::nullopt, 64, std::int64_t{1} << 34, {},
       "cache capacity bytes (overrides the preset)",
       read_cache_size<&CacheGeometry::capacity_bytes>},
      {"memory.cache_ways", T::integer, std::nullopt, 1, 256, {}, "cache associativity (overrides the preset)",
       read_cache_size<&CacheGeometry::ways>},

      {"proxy.share", T::real, std::string("auto"), 1e-6, 1.0, {"auto"},
       "proxy triangles as a share of the scene's, or auto: the paper's 0.02 where the world is paged (memory.budget) "
       "or saved by build, 0.002 in core; a saved world's proxy is simplified again to a smaller share",
       read_proxy_share},
      {"proxy.method", T::text, std::string("auto"), 0, 0, {"auto", "cluster", "stochastic"},
       "simplification: vertex clustering with quadrics, stochastic pruning, or the better of both on test rays",
       choice<parse_proxy_method, &P::proxy, &ProxyOptions::method>},
      {"proxy.accel", T::text, std::string("embree"), 0, 0, {"embree", "bvh"},
       "the proxy's accelerator (bvh: its reads can be observed by [memory])",
       read_proxy_accel},

      {"reorder.heuristic", T::text, std::string("none"), 0, 0,
       {"none", "origin", "origin_dir", "hph", "hph_origin", "hph_dir"}, "ray ordering keys (none: no reordering)",
       choice<parse_reorder_heuristic, &P::reorder, &ZSortOptions::heuristic>},
      {"reorder.curve", T::text, std::string("morton"), 0, 0, {"morton", "hilbert"},
       "space-filling curve of the keys: morton is a little faster in core, hilbert reads fewer pages of a world "
       "paged from its file (docs/reordering.md)",
       choice<parse_curve_kind, &P::reorder, &ZSortOptions::curve>},
      {"reorder.buffer_rays", T::integer, std::int64_t{1} << 18, 1, std::int64_t{1} << 32, {},
       "rays zsort holds before it sorts (it also flushes when it holds every live ray)",
       integer<&P::reorder, &ZSortOptions::buffer_rays>},
      {"reorder.buffer_bytes", T::integer, std::nullopt, 1024, std::int64_t{1} << 40, {},
       "the buffer given in bytes instead (overrides buffer_rays; the paper: 88 MB)",
       read_buffer_bytes},
      {"reorder.buffer", T::text, std::string("memory"), 0, 0, {"memory", "disk"},
       "memory: zsort sorts and emits its buffer whenever it fills; disk (the paper's): the buffer is the in-core "
       "part (88 MB by default), written to sorted runs on disk when full, and every ray of a generation is merged "
       "by key once all live rays wait in it",
       choice<parse_ray_buffer_kind, &P::reorder, &ZSortOptions::buffer>},
      {"reorder.spill_dir", T::text, std::string(""), 0, 0, {},
       "reorder.buffer = disk: the directory of the runs (empty: the system's temporary directory); their files have "
       "no name and vanish with the render",
       text<&P::reorder, &ZSortOptions::spill_dir>},
      {"reorder.sort", T::text, std::string("radix"), 0, 0, {"radix", "parallel"},
       "zsort's sort: a stable LSD radix sort or tbb::parallel_sort",
       read_sort},

      {"pipeline.stages", T::text_list, std::vector<std::string>{"auto"}, 0, 0,
       {"auto", "generate", "approx_hit", "zsort", "repack", "trace", "shade", "spawn"},
       "the stage chain; spawn at the end loops back. auto: the chain reorder.heuristic needs",
       read_stages},
      {"pipeline.mode", T::text, std::string("wavefront"), 0, 0, {"wavefront", "megakernel"},
       "wavefront: batches through the stage graph; megakernel: one path at a time per worker (the control)",
       choice<parse_pipeline_mode, &P::pipeline, &PipelineOptions::mode>},
      {"pipeline.tile", T::integer, std::int64_t{16}, 1, 4096, {},
       "megakernel: side in pixels of the square tiles workers take",
       integer<&P::pipeline, &PipelineOptions::tile_side>},

      {"distribute.mode", T::text, std::string("image"), 0, 0, {"image", "data"},
       "ranks started by mpirun: image (each rank holds the whole world and renders the camera rays rank 0 hands "
       "out on demand; the films are summed exactly: the single process's image) or data (as image, but each rank "
       "owns a run of a chunked world's chunks and rays due at others' chunks travel to their owners); alone, the "
       "whole image",
       choice<parse_distribute_mode, &P::distribute, &DistributePlan::mode>},
      {"distribute.range_rays", T::integer, std::int64_t{0}, 0, std::int64_t{1} << 40, {},
       "camera rays rank 0 hands out at a time (0: the image's rays over 64 ranges a rank, at least "
       "16 batches)",
       integer<&P::distribute, &DistributePlan::range_rays>},
      {"distribute.replicate", T::real, 0.0, 0.0, 1.0, {},
       "data mode: the share of the world's triangles every rank answers itself instead of asking their owner: "
       "the chunks a probe of the view (a coarse image's camera rays and a bounce) asks most a triangle first",
       real<&P::distribute, &DistributePlan::replicate>},
      {"distribute.balance", T::text, std::string("bytes"), 0, 0, {"bytes", "triangles", "rays"},
       "data mode: what the ranks' runs of chunks are weighed by, the heaviest run made as light as it can be: "
       "the bytes of the chunks' structures (a rank's memory), their triangles, or the rays a probe of the view "
       "(a coarse image's camera rays and a bounce) asks of them (work)",
       choice<parse_distribute_balance, &P::distribute, &DistributePlan::balance>},
  };
  return schema;
}

}  // namespace wavetrace
