// Loop subdivision (OpenMesh) to scale real meshes to millions of triangles.
#pragma once

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// The least a subdivided triangle costs to hold and render: a render of a subdivided mesh
// peaked at 106-212 bytes per resulting triangle (data/bunny00.off, 2 to 4 levels, hmq,
// measured by the OS). Subdivision and scene files refuse what memory cannot hold at this.
inline constexpr double kSubdividedBytesPerTriangle = 100.0;

struct SubdivisionResult {
  TriangleMesh mesh;
  std::size_t non_manifold_faces_dropped = 0;  // Loop needs a manifold; these could not enter it
};

// Applies `levels` rounds of Loop subdivision (each multiplies the triangle count by 4).
// Each triangle's material carries over to the triangles it becomes: the triangles of each
// material are subdivided as one surface.
SubdivisionResult loop_subdivide(const TriangleMesh& mesh, int levels);

}  // namespace wavetrace
