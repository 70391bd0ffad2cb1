// Linear-time quadric simplification by vertex clustering (Lindstrom 2000, the out-of-core
// cousin of the paper's clustered edge collapses): a uniform grid over the mesh, one vertex
// per occupied cell placed where the cell's plane quadric is least, and every triangle whose
// corners fall in three different cells kept once. Needs no connectivity (soups simplify
// too) and runs in parallel; thin parts narrower than a cell vanish (builtin:fur).
#pragma once

#include <cstddef>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct ClusterSimplification {
  TriangleMesh mesh;
  double cell_size = 0.0;  // of the grid finally used
  int rounds = 0;          // grid sizes tried to meet the target
};

// About `target_triangles` triangles (within ~15% for surfaces; the grid is refined up to
// four times). Throws SceneError if the mesh is empty.
ClusterSimplification simplify_by_clustering(const TriangleMesh& mesh, std::size_t target_triangles);

}  // namespace wavetrace
