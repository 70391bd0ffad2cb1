// Accelerators by name, as config files, --accel and the bench harness name them.
#pragma once

#include <array>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/bvh_accelerator.hpp"
#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/embree/embree_accelerator.hpp"
#include "wavetrace/accel/grid/array_grid.hpp"
#include "wavetrace/accel/grid/hashed_grid.hpp"
#include "wavetrace/accel/hmq/hmq_accelerator.hpp"
#include "wavetrace/accel/raystrips/raystrips_accelerator.hpp"
#include "wavetrace/accel/tinybvh/tinybvh_accelerator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"
#include "wavetrace/scene/triangle_source.hpp"

namespace wavetrace {

class SectionLoader;

struct AcceleratorOptions {
  std::string type = "embree";
  EmbreeOptions embree;
  BvhOptions bvh;
  HashedGridOptions grid;
  HashedGridOptions mlgrid{32.0, std::size_t{1} << 30, 6};
  ArrayGridOptions arraygrid;
  RayStripsOptions raystrips;
  HmqOptions hmq;
  TinyBvhOptions tinybvh;
  // The kernel set of our walks (memory/kernel_isa.hpp): auto, avx2 or avx512.
  std::string isa = "auto";
  // Scenes of more triangles are built in chunks of at most this many (hmq, raystrips, bvh).
  std::size_t chunk_triangles = std::size_t{1} << 21;
  // At most this many chunks built at the same time; 0: one per thread, as memory allows.
  std::size_t chunks_at_once = 0;
  bool operator==(const AcceleratorOptions&) const = default;
};

// Why accel.type = auto passes a type over on a scene, however fast: the cases where the
// method is known to fail (bench report's stability table measures each).
enum class KnownFailure {
  none,
  triangle_soup,  // strips of one triangle each: no vertex shared
  crowded_cells,  // a grid whose every cell holds many triangles (a dense object in a huge box)
};

// How accel.type = auto (setup/accel_choice.hpp) sees a type.
struct AutoCandidate {
  // Its setting's median speed against robust Embree's on bench report's scenes; 0: never a
  // candidate (the binary layouts, slower at no fewer bytes; grid, slower than mlgrid at the
  // same bytes; arraygrid, larger).
  double relative_speed = 0.0;
  // The setting auto builds (widths, modes; max_error for a lossy type) and its --accel spec.
  void (*set_up)(AcceleratorOptions& options, double max_error) = nullptr;
  std::string (*spec)(double max_error) = nullptr;
  bool lossy = false;                        // hit points within max_error of the mesh, not exact
  bool structure_from_grid_entries = false;  // its bytes follow the grid entries a triangle makes
  bool grows_in_sparse_chunks = false;       // in chunks that share few edges its bytes grow
  KnownFailure failure = KnownFailure::none;
};

// One row of facts per accelerator type: the only place a type's name is compared.
struct AcceleratorType {
  std::string_view name;
  std::unique_ptr<Accelerator> (*make)(const TriangleMesh& mesh, const AcceleratorOptions& options);
  // A structure saved under the loader's prefix with one of `saved_kinds` (SavedKind::type),
  // traced in place; null: the type saves no structure, and a world file rebuilds it from the
  // saved geometry when loaded.
  std::unique_ptr<Accelerator> (*load)(SectionLoader& in, std::string_view kind);
  std::array<std::string_view, 2> saved_kinds;
  bool builds_in_chunks;    // chunk by chunk under a top-level BVH (make_world_accelerator)
  bool holds_own_geometry;  // traces no reference to the input mesh, which can then be released
  // What its finished structure costs per triangle (the most measured on the scenes of
  // docs/memory.md), and what its build holds beyond it per triangle built at once (a chunk,
  // where it builds in chunks): for refusing a scene that will not fit, and for auto.
  double (*bytes_per_triangle)(const AcceleratorOptions& options);
  double build_bytes_per_triangle;
  AutoCandidate automatic;
};

// Every type, in the order config files and error messages list them.
std::span<const AcceleratorType> accelerator_types();
// The row of `name`, or null (accel.type = auto names no type of its own).
const AcceleratorType* find_accelerator_type(std::string_view name);
// The row of `name`; throws std::invalid_argument naming the known types.
const AcceleratorType& accelerator_type(std::string_view name);
std::vector<std::string> accelerator_names();

// Throws std::invalid_argument naming an unknown type or kernel set (options.isa); the
// accelerator walks with that set.
std::unique_ptr<Accelerator> make_accelerator(const TriangleMesh& mesh, const AcceleratorOptions& options);

// The accelerator saved under the loader's prefix (its "kind" names the type), traced in
// place; throws SectionFileError for a type that cannot be loaded or a damaged structure.
std::unique_ptr<Accelerator> load_accelerator(SectionLoader& in);

// The row's facts by name; false for a name that is no type (auto).
bool saves_structure(std::string_view type);
bool builds_in_chunks(std::string_view type);
bool holds_own_geometry(std::string_view type);
// Whether the world's structure over `triangles` would read the scene's whole mesh in place
// (make_world_accelerator): a type that holds no geometry of its own and is built whole. A
// chunked build's chunks keep copies of their meshes, so its scene may be streamed.
bool reads_whole_mesh(const AcceleratorOptions& options, std::uint64_t triangles);
double estimated_bytes_per_triangle(const AcceleratorOptions& options);
double estimated_build_bytes_per_triangle(std::string_view type);

// The world's accelerator over a scene's triangles: chunked (make_chunked_accelerator) when
// the type builds in chunks and the source has more than options.chunk_triangles, else one
// build over `whole` (a mesh the caller keeps alive), or over the source extracted whole
// when `whole` is null. A chunked world saves each chunk to `stream` as it is built
// (ChunkStream); a world built whole ignores it.
std::unique_ptr<Accelerator> make_world_accelerator(const TriangleSource& source, const TriangleMesh* whole,
                                                    const AcceleratorOptions& options,
                                                    const ChunkStream* stream = nullptr);

}  // namespace wavetrace
