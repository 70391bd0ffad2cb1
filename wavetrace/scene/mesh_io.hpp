// Mesh files in: OFF, PLY (ASCII and binary), OBJ and STL, read by our own readers
// (mesh_readers.hpp says why not OpenMesh's).
#pragma once

#include <string>

#include "wavetrace/scene/loaded_mesh.hpp"

namespace wavetrace {

// Reads every face of the file as written (non-manifold faces included, which OpenMesh's
// own mesh kernels would drop), fans polygons into triangles, then validates and cleans.
// Throws SceneError naming the file (and the line, for text formats) on a missing,
// unreadable or malformed file, and naming the file and its size when memory runs out.
LoadedMesh load_mesh_file(const std::string& path);

}  // namespace wavetrace
