// Loop subdivision (OpenMesh) to scale real meshes to millions of triangles.
#pragma once

#include "scene/triangle_mesh.hpp"

namespace wavetrace {

struct SubdivisionResult {
  TriangleMesh mesh;
  std::size_t non_manifold_faces_dropped = 0;  // Loop needs a manifold; these could not enter it
};

// Applies `levels` rounds of Loop subdivision (each multiplies the triangle count by 4).
// Each triangle's material carries over to the triangles it becomes: the triangles of each
// material are subdivided as one surface.
SubdivisionResult loop_subdivide(const TriangleMesh& mesh, int levels);

}  // namespace wavetrace
