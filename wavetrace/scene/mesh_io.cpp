// Loading a mesh file: the format from its extension, the file's bytes to its reader
// (mesh_readers.hpp, or the streaming binary PLY reader), then validation and cleaning.
#include "wavetrace/scene/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <new>

#include <fmt/format.h>

#include "wavetrace/scene/mesh_readers.hpp"
#include "wavetrace/scene/ply_file.hpp"
#include "wavetrace/scene/text_lines.hpp"

namespace wavetrace {

void add_polygon(LoadedMesh& out, std::span<const std::uint32_t> corners) {
  if (corners.size() > 3) ++out.polygons_triangulated;
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
    out.mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
  }
}

namespace {

LoadedMesh read_mesh(const std::string& path, const std::string& extension) {
  LoadedMesh loaded;
  if (extension == ".ply" && is_binary_ply(path)) {
    const PlyTriangleSource source(path);
    loaded.mesh = source.extract(0, source.triangle_count());
    loaded.polygons_triangulated = source.polygons_triangulated();
    loaded.cleanup.degenerate_dropped = source.degenerate_dropped();
    return loaded;
  }
  const std::string bytes = read_whole_file(path);
  if (extension == ".off") read_off(bytes, path, loaded);
  else if (extension == ".obj") read_obj(bytes, path, loaded);
  else if (extension == ".stl") read_stl(bytes, path, loaded);
  else read_text_ply(bytes, path, loaded);
  return loaded;
}

}  // namespace

LoadedMesh load_mesh_file(const std::string& path) {
  std::error_code status;
  if (!std::filesystem::is_regular_file(path, status)) {
    throw SceneError(fmt::format("{}: no such mesh file", path));
  }
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension != ".off" && extension != ".ply" && extension != ".obj" && extension != ".stl") {
    throw SceneError(fmt::format("{}: unsupported mesh format (use .off, .ply, .obj or .stl)", path));
  }
  try {
    LoadedMesh loaded = read_mesh(path, extension);
    const std::size_t dropped_while_reading = loaded.cleanup.degenerate_dropped;
    loaded.cleanup = validate_and_clean(loaded.mesh, path);
    loaded.cleanup.degenerate_dropped += dropped_while_reading;
    return loaded;
  } catch (const std::bad_alloc&) {
    throw SceneError(fmt::format("{}: out of memory loading the mesh ({} bytes of file)", path,
                                 std::filesystem::file_size(path, status)));
  }
}

}  // namespace wavetrace
