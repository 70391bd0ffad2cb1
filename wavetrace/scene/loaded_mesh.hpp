// A mesh file as read: its mesh, with what the reader had to fan or clean on the way.
#pragma once

#include <cstddef>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct LoadedMesh {
  TriangleMesh mesh;
  std::size_t polygons_triangulated = 0;  // faces of more than 3 corners, fanned into triangles
  MeshCleanup cleanup;
};

}  // namespace wavetrace
