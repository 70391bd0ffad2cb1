// Loop subdivision (OpenMesh) to scale real meshes to millions of triangles.
#pragma once

#include "scene/triangle_mesh.hpp"

namespace wavetrace {

struct SubdivisionResult {
  TriangleMesh mesh;
  std::size_t non_manifold_faces_dropped = 0;  // Loop needs a manifold; these could not enter it
};

// Applies `levels` rounds of Loop subdivision (each multiplies the triangle count by 4).
// Material indices do not survive subdivision: the result uses the first triangle's material.
SubdivisionResult loop_subdivide(const TriangleMesh& mesh, int levels);

}  // namespace wavetrace
