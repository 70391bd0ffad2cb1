// The table of accelerator types: how each is made, loaded and estimated, and how auto sees it.
#include "wavetrace/accel/registry.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/kernels/checked_narrowing.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"

namespace wavetrace {
namespace {

// Build temporaries per triangle built at once. Embree's builder: VmHWM 0.26 GB above the
// finished render's resident memory on room:8M (its allocation monitor said ~15 B/tri on
// room:64M); ours, the binned SAH build's arrays and the chunk's mesh: 165 B/tri on a
// monolithic room:64M, 180 per chunk triangle for bvh:width=8 on room:8M. In chunks of 125k on
// room:1M and sphere:1M (render VmHWM less an empty render's 18 MB and the finished structure,
// over the two chunks built at once): hmq:width=8 147 and 196, raystrips:width=8 174 and 182,
// bvh:width=8 266 and 221. These are not each an upper bound: auto's estimate adds them to a
// structure and a process allowance that are (12.5 and 22 B/tri against 9-15 measured, 32 MB
// against 18), and `bench report` sets every candidate's sum against its measured render peak.
// The grids' counting build holds a count per cell and the lists' positions (bench accel saw
// no VmHWM rise above its start on builtin:sphere:1M): bounded here by a cell count.
constexpr double kSahBuildBytesPerTriangle = 165.0;
// hmq:width=8's build since its leaves went to both cores, its node slots stopped being copied
// and its untouched slots stopped being touched (2026-12-04; render VmHWM less an empty
// render's 19.7 MB and the finished structure): 66 B/tri on room:1M built whole, 51 and 57 a
// chunk triangle on room:8M with two chunks and one chunk built at once. With margin:
constexpr double kHmqBuildBytesPerTriangle = 80.0;

std::unique_ptr<Accelerator> make_mlgrid(const TriangleMesh& mesh, const AcceleratorOptions& options) {
  if (options.mlgrid.macrocell_factor < 2) throw std::invalid_argument("mlgrid needs a macrocell factor of 2 or more");
  return make_hashed_grid_accelerator(mesh, options.mlgrid);
}

std::unique_ptr<Accelerator> load_hmq(SectionLoader& in, std::string_view kind) {
  return kind == "hmq8" ? load_wide_hmq_accelerator(in) : load_hmq_accelerator(in);
}

// Finished structures per triangle: the largest of docs/memory.md's tables (room, subdivided
// scans; chunked room up to 256M).
double grid_bytes(const AcceleratorOptions&) { return 48.0; }  // cells and lists vary; 44 on builtin:sphere:1M

// Auto's speeds: medians against robust Embree of `bench accel --threads 2` on room:1M,
// sphere:1M and bunny00 x2, camera and diffuse rays (measurements.md, "Auto's speeds,
// measured again", 2026-12-07; the ranges beside each row are those runs').
const AcceleratorType kTypes[] = {
    {"embree",
     [](const TriangleMesh& mesh, const AcceleratorOptions& options) { return make_embree_accelerator(mesh, options.embree); },
     nullptr, {}, false, false,
     [](const AcceleratorOptions& options) { return options.embree.mode == EmbreeMode::compact ? 78.0 : 87.0; }, 32.0,
     {.relative_speed = 1.0,  // robust
      .set_up = [](AcceleratorOptions& options, double) { options.embree.mode = EmbreeMode::robust; },
      .spec = [](double) { return std::string("embree:mode=robust"); }}},
    {"bvh", [](const TriangleMesh& mesh, const AcceleratorOptions& options) { return make_bvh_accelerator(mesh, options.bvh); },
     [](SectionLoader& in, std::string_view) { return load_bvh_accelerator(in); }, {"bvh"}, true, false,
     // width 8, leaves of up to 16: 67.9-69.3 on the rooms and the scans
     [](const AcceleratorOptions& options) { return options.bvh.width == 8 ? 69.0 : 60.0; }, 190.0,
     {.relative_speed = 1.10,  // width 8: 1.04 - 1.22
      .set_up = [](AcceleratorOptions& options, double) { options.bvh.width = 8; },
      .spec = [](double) { return std::string("bvh:width=8"); }}},
    {"raystrips",
     [](const TriangleMesh& mesh, const AcceleratorOptions& options) {
       return make_raystrips_accelerator(mesh, options.raystrips);
     },
     [](SectionLoader& in, std::string_view) { return load_raystrips_accelerator(in); }, {"raystrips"}, true, true,
     // binary: 22.1 on room:8M, 25.7 on 256M
     [](const AcceleratorOptions& options) { return options.raystrips.width == 8 ? 22.0 : 26.0; },
     kSahBuildBytesPerTriangle,
     {.relative_speed = 0.70,  // width 8: 0.64 - 0.80
      .set_up = [](AcceleratorOptions& options, double) { options.raystrips.width = 8; },
      .spec = [](double) { return std::string("raystrips:width=8"); },
      .grows_in_sparse_chunks = true,
      .failure = KnownFailure::triangle_soup}},
    {"hmq", [](const TriangleMesh& mesh, const AcceleratorOptions& options) { return make_hmq_accelerator(mesh, options.hmq); },
     load_hmq, {"hmq", "hmq8"}, true, true, [](const AcceleratorOptions&) { return 12.5; }, kHmqBuildBytesPerTriangle,
     {.relative_speed = 0.90,  // width 8: 0.81 - 1.04
      .set_up =
          [](AcceleratorOptions& options, double max_error) {
            options.hmq.width = 8;
            options.hmq.bits = HmqOptions{}.bits;
            options.hmq.epsilon = max_error;
          },
      .spec = [](double max_error) { return fmt::format("hmq:width=8:epsilon={:.6g}", max_error); },
      .lossy = true}},
    {"grid",
     [](const TriangleMesh& mesh, const AcceleratorOptions& options) { return make_hashed_grid_accelerator(mesh, options.grid); },
     nullptr, {}, false, false, grid_bytes, 24.0, {}},
    {"mlgrid", make_mlgrid, nullptr, {}, false, false, grid_bytes, 24.0,
     {.relative_speed = 0.24,  // 0.15 - 0.28 (room's empty space is its slowest)
      .set_up = [](AcceleratorOptions&, double) {},
      .spec = [](double) { return std::string("mlgrid"); },
      .structure_from_grid_entries = true,
      .failure = KnownFailure::crowded_cells}},
    {"arraygrid",
     [](const TriangleMesh& mesh, const AcceleratorOptions& options) {
       return make_array_grid_accelerator(mesh, options.arraygrid);
     },
     nullptr, {}, false, false, [](const AcceleratorOptions&) { return 230.0; },  // 224 on builtin:sphere:1M
     kSahBuildBytesPerTriangle, {}},
    // A peer, not a candidate: in the harness beside our walks when built in (-DWAVETRACE_TINYBVH).
    // bvh8 keeps the binary and 8-wide trees it converted from: 317 B/tri on bunny00
    // subdivided twice, 298 on room:1M (72.5 of them walked); bvh 88.0 and 88.4. Their builds'
    // resident peaks stayed below the finished bytes (360 against 382 MB; 84 against 106).
    {"tinybvh",
     [](const TriangleMesh& mesh, const AcceleratorOptions& options) {
       return make_tinybvh_accelerator(mesh, options.tinybvh);
     },
     nullptr, {}, false, false,
     [](const AcceleratorOptions& options) { return options.tinybvh.layout == TinyBvhLayout::bvh8 ? 317.0 : 89.0; },
     0.0, {}},
};

}  // namespace

std::span<const AcceleratorType> accelerator_types() { return kTypes; }

const AcceleratorType* find_accelerator_type(std::string_view name) {
  const auto row = std::find_if(std::begin(kTypes), std::end(kTypes), [&](const AcceleratorType& t) { return t.name == name; });
  return row == std::end(kTypes) ? nullptr : &*row;
}

std::vector<std::string> accelerator_names() {
  std::vector<std::string> names;
  for (const AcceleratorType& type : kTypes) names.emplace_back(type.name);
  return names;
}

const AcceleratorType& accelerator_type(std::string_view name) {
  if (const AcceleratorType* row = find_accelerator_type(name)) return *row;
  std::string known;
  for (const AcceleratorType& type : kTypes) known += (known.empty() ? "" : ", ") + std::string(type.name);
  throw std::invalid_argument(fmt::format("unknown accelerator '{}' (available: {})", name, known));
}

bool saves_structure(std::string_view type) {
  const AcceleratorType* row = find_accelerator_type(type);
  return row != nullptr && row->load != nullptr;
}
bool builds_in_chunks(std::string_view type) {
  const AcceleratorType* row = find_accelerator_type(type);
  return row != nullptr && row->builds_in_chunks;
}
bool holds_own_geometry(std::string_view type) {
  const AcceleratorType* row = find_accelerator_type(type);
  return row != nullptr && row->holds_own_geometry;
}
bool reads_whole_mesh(const AcceleratorOptions& options, std::uint64_t triangles) {
  const AcceleratorType& type = accelerator_type(options.type);
  const bool chunked = type.builds_in_chunks && triangles > options.chunk_triangles;  // as build_for_world decides
  return !type.holds_own_geometry && !chunked;
}
double estimated_bytes_per_triangle(const AcceleratorOptions& options) {
  return accelerator_type(options.type).bytes_per_triangle(options);
}
double estimated_build_bytes_per_triangle(std::string_view type) { return accelerator_type(type).build_bytes_per_triangle; }

namespace {

std::unique_ptr<Accelerator> with_kernels(std::unique_ptr<Accelerator> accelerator, KernelIsa isa) {
  accelerator->use_isa(isa);
  return accelerator;
}

std::unique_ptr<Accelerator> build_for_world(const TriangleSource& source, const TriangleMesh* whole,
                                             const AcceleratorOptions& options, const ChunkStream* stream) {
  checked_uint32(source.triangle_count(), "triangles of a scene, which hits name by 32-bit ids");
  const AcceleratorType& type = accelerator_type(options.type);
  AcceleratorOptions chunk_options = options;
  chunk_options.hmq.grid_bounds = source.bounds();  // one global grid, whether chunked or not
  if (type.builds_in_chunks && source.triangle_count() > options.chunk_triangles) {
    return make_chunked_accelerator(
        source, options.chunk_triangles,
        [&](const TriangleMesh& chunk) { return type.make(chunk, chunk_options); }, !type.holds_own_geometry, stream,
        options.chunks_at_once);
  }
  if (whole != nullptr) return type.make(*whole, chunk_options);
  if (!type.holds_own_geometry) {
    throw std::logic_error(fmt::format("'{}' reads its mesh in place: the caller must keep the whole mesh", options.type));
  }
  const TriangleMesh mesh = source.extract(0, source.triangle_count());
  return type.make(mesh, chunk_options);
}

}  // namespace

std::unique_ptr<Accelerator> make_world_accelerator(const TriangleSource& source, const TriangleMesh* whole,
                                                    const AcceleratorOptions& options, const ChunkStream* stream) {
  const KernelIsa isa = parse_kernel_isa(options.isa);  // a bad setting fails before the build, not after it
  return with_kernels(build_for_world(source, whole, options, stream), isa);
}

std::unique_ptr<Accelerator> load_accelerator(SectionLoader& in) {
  const SavedKind kind = in.file()->value<SavedKind>(in.prefix() + "kind");
  const std::string name(kind.type, strnlen(kind.type, sizeof(kind.type)));
  if (name == kChunkedKind) return load_chunked_accelerator(in, [](SectionLoader& chunk) { return load_accelerator(chunk); });
  for (const AcceleratorType& type : kTypes) {
    if (type.load != nullptr && std::find(type.saved_kinds.begin(), type.saved_kinds.end(), name) != type.saved_kinds.end()) {
      return type.load(in, name);
    }
  }
  in.fail("kind", fmt::format("names accelerator '{}', which this build cannot load", name));
}

std::unique_ptr<Accelerator> make_accelerator(const TriangleMesh& mesh, const AcceleratorOptions& options) {
  const KernelIsa isa = parse_kernel_isa(options.isa);  // before the build, as above
  return with_kernels(accelerator_type(options.type).make(mesh, options), isa);
}

}  // namespace wavetrace
