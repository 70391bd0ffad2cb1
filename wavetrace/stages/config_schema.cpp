// The schema: every configuration key, its type, default and valid range. Adding a
// feature's option means adding one line here and one row in plan_keys.cpp's table, which
// says where the value goes (PlanKeys.EverySchemaKeyHasOneRowAndEveryRowAKey checks both).
#include "wavetrace/stages/config.hpp"
#include "wavetrace/stages/pipeline.hpp"

namespace wavetrace {

const std::vector<std::string>& config_sections() {
  static const std::vector<std::string> sections = {"scene", "camera", "render", "accel", "build",
                                                    "proxy", "reorder", "memory", "pipeline"};
  return sections;
}

const std::vector<ConfigKey>& config_schema() {
  using T = ConfigType;
  static const std::vector<ConfigKey> schema = {
      {"scene.source", T::text, std::string("builtin:default"), 0, 0, {},
       "mesh file (.off .ply .obj .stl), scene file (.toml) or builtin:NAME[:TRIANGLES]"},
      {"scene.subdivide", T::integer, std::int64_t{0}, 0, 6, {}, "levels of Loop subdivision after loading"},

      {"camera.position", T::vector3, std::nullopt, 0, 0, {}, "eye point (default: the scene's or framed)"},
      {"camera.look_at", T::vector3, std::nullopt, 0, 0, {}, "point looked at"},
      {"camera.up", T::vector3, std::nullopt, 0, 0, {}, "up direction (default: the scene's, or +y)"},
      {"camera.fov", T::real, std::nullopt, 1, 179, {}, "vertical field of view in degrees"},

      {"render.width", T::integer, std::int64_t{640}, 1, 16384, {}, "image width in pixels"},
      {"render.height", T::integer, std::int64_t{480}, 1, 16384, {}, "image height in pixels"},
      {"render.spp", T::integer, std::int64_t{8}, 1, 65536, {}, "samples per pixel"},
      {"render.seed", T::integer, std::int64_t{0}, 0, 1 << 20, {},
       "which samples are drawn: seed k draws samples k*spp .. (k+1)*spp - 1 of each pixel (another seed, "
       "independent noise)"},
      {"render.max_depth", T::integer, std::int64_t{5}, 0, 64, {},
       "most bounces of a path (0: direct light only)"},
      {"render.russian_roulette_depth", T::integer, std::int64_t{3}, 0, 64, {},
       "bounce depth from which Russian roulette may end a path"},
      {"render.threads", T::integer, std::int64_t{0}, 0, 1024, {}, "worker threads (0: all cores)"},
      {"render.batch_size", T::integer, std::int64_t{kPipelineBatchSize}, 16, 1 << 20, {},
       "rays per batch (1024: a batch and its hits, ~100 KB, stay in L2 between stages)"},
      {"render.rays_in_flight", T::integer, std::nullopt, 1024, std::int64_t{1} << 30, {},
       "most rays alive at once (bounds memory); default: reorder.buffer_rays with zsort in the chain, else 4 "
       "batches per worker"},
      {"render.film", T::text, std::string("shared"), 0, 0, {"shared", "per_thread"},
       "shared: one film, atomic adds; per_thread: a film per worker, summed at the end (same image)"},
      {"render.pixel_order", T::text, std::string("scanline"), 0, 0, {"scanline", "zcurve"},
       "order in which camera rays are generated"},

      {"accel.type", T::text, std::string("embree"), 0, 0,
       {"embree", "bvh", "raystrips", "hmq", "grid", "mlgrid", "arraygrid", "auto"},
       "main accelerator (auto: the fastest that fits accel.memory_budget and meets accel.max_error)"},
      {"accel.memory_budget", T::text, std::string("available"), 0, 0, {},
       "what accel.type = auto may spend on the world (structure, mesh, build): bytes ('8GB', '512MiB'), a share "
       "of the memory available now ('50%'), or 'available' (what is available now, less 10%)"},
      {"accel.max_error", T::real, std::string("pixel"), 0.0, 1e30, {"pixel"},
       "largest hit-point error accel.type = auto may accept, in scene units (0: exact methods only), or pixel: half "
       "a pixel's footprint at the nearest surface in view"},
      {"accel.embree.mode", T::text, std::string("default"), 0, 0, {"default", "compact", "robust"},
       "Embree scene flags"},
      {"accel.embree.queries", T::text, std::string("stream"), 0, 0, {"single", "stream"},
       "rtcIntersect1 per ray, or a batch range through rtcIntersectNp (camera rays flagged coherent)"},
      {"accel.bvh.leaf_size", T::integer, std::int64_t{4}, 1, 16, {}, "most triangles per BVH leaf"},
      {"accel.bvh.layout", T::text, std::string("depth_first"), 0, 0, {"depth_first", "breadth_first", "veb"},
       "BVH node order in memory"},
      {"accel.bvh.triangle_order", T::text, std::string("input"), 0, 0, {"input", "morton", "leaf"},
       "the BVH's indexed face set: the mesh's (input), a Morton-sorted copy, or a copy in leaf order"},
      {"accel.bvh.bins", T::integer, std::int64_t{16}, 2, 64, {}, "SAH bins per axis"},
      {"accel.grid.density", T::real, 32.0, 0.01, 4096.0, {}, "cells per triangle (Woo's heuristic; the paper: 32)"},
      {"accel.grid.max_cells", T::integer, std::int64_t{1} << 30, 1, std::int64_t{1} << 36, {},
       "resolution guard: most cells of the grid (the density is lowered to fit)"},
      {"accel.mlgrid.density", T::real, 32.0, 0.01, 4096.0, {}, "cells per triangle of mlgrid's fine grid"},
      {"accel.mlgrid.max_cells", T::integer, std::int64_t{1} << 30, 1, std::int64_t{1} << 36, {},
       "resolution guard of mlgrid"},
      {"accel.mlgrid.macrocell_factor", T::integer, std::int64_t{6}, 2, 64, {},
       "fine cells per macrocell side, per level (the paper: 6)"},
      {"accel.arraygrid.density", T::real, 4.0, 0.01, 4096.0, {}, "cells per triangle of each nested grid (the paper: 4)"},
      {"accel.arraygrid.refine_items", T::integer, std::int64_t{8}, 2, 1 << 20, {},
       "a cell holding this many triangles is refined"},
      {"accel.arraygrid.max_depth", T::integer, std::int64_t{2}, 0, 4, {}, "deepest nested grid (root: 0)"},
      {"accel.arraygrid.max_cells", T::integer, std::int64_t{1} << 28, 1, std::int64_t{1} << 34, {},
       "resolution guard: refinement stops once the grids hold this many cells"},
      {"accel.arraygrid.max_entries", T::integer, std::int64_t{1} << 28, 1, std::int64_t{1} << 34, {},
       "resolution guard: refinement stops once the triangle lists made hold this many entries"},
      {"accel.raystrips.submesh_triangles", T::integer, std::int64_t{256}, 2, 65535, {},
       "sub-mesh threshold: the SAH tree is cut where a subtree holds at most this many triangles, then stripified"},
      {"accel.raystrips.stripifier", T::text, std::string("openmesh"), 0, 0, {"dual_path", "openmesh"},
       "dual_path: ours (long, compact strips); openmesh: OpenMesh's StripifierT"},
      {"accel.raystrips.strips_per_leaf", T::integer, std::int64_t{1}, 1, 16, {},
       "most strips per top BVH leaf (1: the paper's one strip per leaf)"},
      {"accel.raystrips.run_triangles", T::integer, std::int64_t{6}, 2, 64, {},
       "the strip's kd-tree is descended to spans of at most this many triangles, tested together (the paper: 2)"},
      {"accel.raystrips.packets", T::boolean, true, 0, 0, {}, "camera rays as 2x2 packets"},
      {"accel.raystrips.width", T::integer, std::int64_t{2}, 2, 8, {},
       "top over the strips: 2, binary 32-byte nodes; 8, quantized 8-wide nodes (no packets)"},
      {"accel.raystrips.packet_min_active", T::integer, std::int64_t{2}, 1, 4, {},
       "below this many active rays a packet continues as single rays"},
      {"accel.hmq.bits", T::integer, std::int64_t{16}, 1, 24, {}, "global grid bits per axis (the paper: 16)"},
      {"accel.hmq.epsilon", T::real, 0.0, 0.0, 1e30, {"pixel"},
       "error bound in scene units instead of bits (0: unset), or pixel: half a pixel's footprint at the nearest "
       "surface in view; the grid is the coarsest that keeps every vertex within it"},
      {"accel.hmq.leaf_size", T::integer, std::int64_t{8}, 1, 14, {}, "most triangles per leaf (the paper: 4, 8, 12)"},
      {"accel.hmq.top_fraction", T::real, 0.05, 0.0, 1.0, {},
       "share of the BVH's nodes kept uncompressed at the top (width 2 only)"},
      {"accel.hmq.width", T::integer, std::int64_t{2}, 2, 8, {},
       "2: the paper's binary 4-byte nodes in blocks; 8: 64-byte nodes of 8 children, 8-bit planes, AVX2"},
      {"accel.bvh.width", T::integer, std::int64_t{2}, 2, 8, {}, "2: binary 32-byte nodes; 8: AVX2 8-wide nodes"},

      {"build.chunk_triangles", T::integer, std::int64_t{1} << 22, std::int64_t{1024}, std::int64_t{1} << 30, {},
       "scenes of more triangles are built in chunks of at most this many under a top BVH (hmq, raystrips, bvh)"},

      {"memory.budget", T::text, std::string("none"), 0, 0, {},
       "simulated page pool: none, a share of the world (20%) or a size (512MiB, 2GB)"},
      {"memory.page_bytes", T::integer, std::int64_t{4} << 20, 4096, std::int64_t{1} << 30, {},
       "page size of the pool in bytes, a power of two (the paper: 4 MiB)"},
      {"memory.backing", T::text, std::string("memory"), 0, 0, {"memory", "file"},
       "where a world file's pages live: memory (mapped, the OS pages it) or file (real paging: read on demand "
       "with O_DIRECT into a pool of memory.budget, evicted LRU)"},
      {"memory.io", T::text, std::string("disk"), 0, 0, {"disk", "nvme"},
       "simulated device per fault: disk (the paper's, 101 MB/s, 8 ms) or nvme (3.5 GB/s, 80 us)"},
      {"memory.cache", T::text, std::string("none"), 0, 0, {"none", "paper_l2", "l1d", "l2", "custom"},
       "simulated cache per thread: paper_l2 (6 MiB, 24-way), l1d (32 KiB, 8-way), l2 (512 KiB, 8-way)"},
      {"memory.cache_line_bytes", T::integer, std::nullopt, 4, 4096, {}, "cache line bytes (overrides the preset)"},
      {"memory.cache_bytes", T::integer, std::nullopt, 64, std::int64_t{1} << 34, {},
       "cache capacity bytes (overrides the preset)"},
      {"memory.cache_ways", T::integer, std::nullopt, 1, 256, {}, "cache associativity (overrides the preset)"},

      {"proxy.share", T::real, 0.02, 1e-6, 1.0, {}, "proxy triangles as a share of the scene's (the paper: 0.02)"},
      {"proxy.method", T::text, std::string("auto"), 0, 0, {"auto", "cluster", "stochastic"},
       "simplification: vertex clustering with quadrics, stochastic pruning, or the better of both on test rays"},
      {"proxy.accel", T::text, std::string("embree"), 0, 0, {"embree", "bvh"},
       "the proxy's accelerator (bvh: its reads can be observed by [memory])"},

      {"reorder.heuristic", T::text, std::string("none"), 0, 0,
       {"none", "origin", "origin_dir", "hph", "hph_origin", "hph_dir"}, "ray ordering keys (none: no reordering)"},
      {"reorder.curve", T::text, std::string("morton"), 0, 0, {"morton", "hilbert"}, "space-filling curve of the keys"},
      {"reorder.buffer_rays", T::integer, std::int64_t{1} << 18, 1, std::int64_t{1} << 32, {},
       "rays zsort holds before it sorts (it also flushes when it holds every live ray)"},
      {"reorder.buffer_bytes", T::integer, std::nullopt, 1024, std::int64_t{1} << 40, {},
       "the buffer given in bytes instead (overrides buffer_rays; the paper: 88 MB)"},
      {"reorder.sort", T::text, std::string("radix"), 0, 0, {"radix", "parallel"},
       "zsort's sort: a stable LSD radix sort or tbb::parallel_sort"},

      {"pipeline.stages", T::text_list, std::vector<std::string>{"auto"}, 0, 0,
       {"auto", "generate", "approx_hit", "zsort", "repack", "trace", "shade", "spawn"},
       "the stage chain; spawn at the end loops back. auto: the chain reorder.heuristic needs"},
      {"pipeline.mode", T::text, std::string("wavefront"), 0, 0, {"wavefront", "megakernel"},
       "wavefront: batches through the stage graph; megakernel: one path at a time per worker (the control)"},
      {"pipeline.tile", T::integer, std::int64_t{16}, 1, 4096, {},
       "megakernel: side in pixels of the square tiles workers take"},
  };
  return schema;
}

}  // namespace wavetrace
