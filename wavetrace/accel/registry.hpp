// Accelerators by name, as config files, --accel and the bench harness name them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/bvh_accelerator.hpp"
#include "wavetrace/accel/embree/embree_accelerator.hpp"
#include "wavetrace/accel/grid/array_grid.hpp"
#include "wavetrace/accel/grid/hashed_grid.hpp"
#include "wavetrace/accel/hmq/hmq_accelerator.hpp"
#include "wavetrace/accel/raystrips/raystrips_accelerator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"
#include "wavetrace/scene/triangle_source.hpp"

namespace wavetrace {

struct AcceleratorOptions {
  std::string type = "embree";
  EmbreeOptions embree;
  BvhOptions bvh;
  HashedGridOptions grid;
  HashedGridOptions mlgrid{32.0, std::size_t{1} << 30, 6};
  ArrayGridOptions arraygrid;
  RayStripsOptions raystrips;
  HmqOptions hmq;
  // Scenes of more triangles are built in chunks of at most this many (hmq, raystrips, bvh).
  std::size_t chunk_triangles = std::size_t{1} << 22;
};

std::vector<std::string> accelerator_names();

// Throws std::invalid_argument naming an unknown type.
std::unique_ptr<Accelerator> make_accelerator(const TriangleMesh& mesh, const AcceleratorOptions& options);

// The accelerator saved under the loader's prefix (its "kind" names the type), traced in
// place; throws SectionFileError for a type that cannot be loaded or a damaged structure.
class SectionLoader;
std::unique_ptr<Accelerator> load_accelerator(SectionLoader& in);
// Types whose built structure can be saved and traced in place from a world file; the
// others (embree, the grids) are rebuilt from the world's saved geometry when it is loaded.
bool saves_structure(const std::string& type);

// What an accelerator's finished structure costs per triangle (the most measured on the
// README's scenes), and what its build holds beyond it per triangle built at once (a chunk,
// where the type builds in chunks; README, "Memory at scale"): for refusing a scene that will
// not fit, and for accel.type = auto, before building it.
double estimated_bytes_per_triangle(const AcceleratorOptions& options);
double estimated_build_bytes_per_triangle(const std::string& type);

// Types that can be built chunk by chunk under a top-level BVH.
bool builds_in_chunks(const std::string& type);
// Types whose structure holds the geometry it traces (no reference to the input mesh), so
// the mesh can be released once they are built and need never exist whole.
bool holds_own_geometry(const std::string& type);

// The world's accelerator over a scene's triangles: chunked (make_chunked_accelerator) when
// the type builds in chunks and the source has more than options.chunk_triangles, else one
// build over `whole` (a mesh the caller keeps alive), or over the source extracted whole
// when `whole` is null.
std::unique_ptr<Accelerator> make_world_accelerator(const TriangleSource& source, const TriangleMesh* whole,
                                                    const AcceleratorOptions& options);

}  // namespace wavetrace
