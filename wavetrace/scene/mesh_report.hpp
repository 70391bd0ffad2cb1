// Topology and geometry facts about a mesh, as `wavetrace info` prints them.
#pragma once

#include <cstddef>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct MeshReport {
  std::size_t triangles = 0;
  std::size_t vertices = 0;
  Bounds3 bounds;
  std::size_t connected_components = 0;  // triangles joined through shared vertices
  std::size_t edges = 0;
  std::size_t boundary_edges = 0;      // used by one triangle
  std::size_t non_manifold_edges = 0;  // used by three or more triangles
  std::size_t degenerate_triangles = 0;

  // Closed: every edge is shared by exactly two triangles.
  bool closed() const { return boundary_edges == 0 && non_manifold_edges == 0; }
};

MeshReport analyze_mesh(const TriangleMesh& mesh);

}  // namespace wavetrace
