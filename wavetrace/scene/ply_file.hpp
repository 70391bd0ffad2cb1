// Binary PLY without an in-memory polygon mesh: a streaming reader (a TriangleSource: the
// vertex positions are held, 12 bytes each, and faces are read a range at a time as a
// chunked build asks for them) and a writer that exports any scene a piece at a time.
// ASCII PLY is read whole (mesh_io.hpp). No PLY library is packaged for Debian 12, so this
// reader is ours; it reads the header of ply_header.hpp in binary_little_endian or
// binary_big_endian form, with the vertices before the faces and only elements of
// fixed-size scalar records before the faces (others after them are never read).
//
// Written files use that form, binary_little_endian, with float coordinates and uchar/uint lists,
// little-endian. Polygons are fanned into triangles (v0, vk, vk+1); triangles with a
// repeated corner or zero area are dropped and counted, as validate_and_clean does.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "wavetrace/scene/triangle_source.hpp"

namespace wavetrace {

// Whether the file starts with a binary PLY header (false for ASCII PLY and other files).
bool is_binary_ply(const std::string& path);

class PlyTriangleSource final : public TriangleSource {
 public:
  // Reads the header and the vertices, and counts the triangles in one pass over the faces,
  // checking every index. Throws SceneError naming the file and the problem.
  explicit PlyTriangleSource(const std::string& path);

  std::size_t triangle_count() const override { return triangles_; }
  Bounds3 bounds() const override { return bounds_; }
  std::vector<std::size_t> object_starts() const override { return {0}; }
  // Reads faces from the file; fastest when ranges are asked for in increasing order.
  TriangleMesh extract(std::size_t first, std::size_t count) const override;

  std::size_t vertex_count() const { return positions_.size(); }
  std::size_t polygons_triangulated() const { return polygons_triangulated_; }
  std::size_t degenerate_dropped() const { return degenerate_dropped_; }

  struct Layout;  // the parsed header (ply_file.cpp)
  struct Cursor;  // where the last extract stopped reading faces

 private:
  std::string path_;
  std::vector<glm::vec3> positions_;
  Bounds3 bounds_;
  std::size_t triangles_ = 0, polygons_triangulated_ = 0, degenerate_dropped_ = 0;
  std::shared_ptr<const Layout> layout_;
  mutable std::mutex cursor_mutex_;
  mutable std::shared_ptr<Cursor> cursor_;
};

// Writes `source` to `path` as binary little-endian PLY, `piece_triangles` at a time (a
// piece's vertices are its own: a vertex on a piece border is written once per piece, at
// the same position). Returns the vertices written. Throws SceneError on an I/O failure.
std::size_t write_binary_ply(const TriangleSource& source, const std::string& path, std::size_t piece_triangles);

}  // namespace wavetrace
