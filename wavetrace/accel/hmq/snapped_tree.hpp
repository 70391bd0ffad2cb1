// What both HMQ layouts (binary blocks and 8-wide nodes) build first: the options checked,
// the global grid, every vertex snapped to it, and the SAH tree over the snapped triangles.
#pragma once

#include <cstddef>

#include "wavetrace/accel/build_phases.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hmq/hmq_options.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"
#include "wavetrace/accel/hmq/leaf_codec.hpp"

namespace wavetrace::hmq {

// Bytes of either layout by part, as MemoryReport gives them.
struct PartBytes {
  std::size_t hierarchy = 0, geometry = 0, other = 0;
};

struct SnappedTree {
  GlobalGrid grid;
  QuantizedMesh quantized;
  BuildTree tree;
  std::size_t peak_bytes = 0;  // the tree build's working memory at its peak, bounds included
  BuildPhases phases;          // "snap" (vertices and triangle boxes), "sah"
};

// Throws std::invalid_argument for options outside their ranges or an empty mesh.
void check_options(const HmqOptions& options);
SnappedTree build_snapped_tree(const TriangleMesh& mesh, const HmqOptions& options);
// The mesh either layout represents: every vertex moved to its grid point.
TriangleMesh snapped_mesh(const GlobalGrid& grid, const TriangleMesh& source);

}  // namespace wavetrace::hmq
