// The OFF reader of mesh_readers.hpp.
#include <algorithm>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "wavetrace/scene/mesh_readers.hpp"
#include "wavetrace/scene/text_lines.hpp"

namespace wavetrace {
namespace {

// "OFF" with any of the optional prefixes ST, C, N, 4, n in that order.
bool is_off_keyword(std::string_view keyword) {
  if (!keyword.ends_with("OFF")) return false;
  keyword.remove_suffix(3);
  for (const std::string_view prefix : {"ST", "C", "N", "4", "n"}) {
    if (keyword.starts_with(prefix)) keyword.remove_prefix(prefix.size());
  }
  return keyword.empty();
}

}  // namespace

void read_off(std::string_view text, const std::string& path, LoadedMesh& out) {
  TextLines lines(text, path);
  std::vector<std::string_view> fields;
  if (!lines.next(fields)) lines.fail("the file ends before the OFF keyword");
  const std::string_view keyword = fields[0];
  if (!is_off_keyword(keyword)) lines.fail(fmt::format("not an OFF file (it must start with OFF, not '{}')", keyword.substr(0, 20)));
  if (keyword.find_first_of("4n") != std::string_view::npos) {
    lines.fail(fmt::format("{} (4- or n-dimensional vertices) is not supported", keyword));
  }
  if (fields.size() > 1 && fields[1] == "BINARY") lines.fail("binary OFF is not supported (convert the mesh to PLY)");
  if (fields.size() == 1 && !lines.next(fields)) lines.fail("the file ends before the vertex and face counts");
  const std::size_t first_count = fields[0] == keyword ? 1 : 0;
  if (fields.size() < first_count + 2) lines.fail("the counts line needs a vertex count and a face count");
  constexpr std::int64_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();
  const auto vertices = static_cast<std::size_t>(lines.integer(fields[first_count], "the vertex count", 0, kMaxVertices));
  const auto faces = static_cast<std::size_t>(lines.integer(fields[first_count + 1], "the face count", 0, std::int64_t{1} << 40));
  // The counts are untrusted: reserve no more than the file could hold (a vertex line is at
  // least 6 bytes, "0 0 0\n", a face line 8).
  out.mesh.positions.reserve(std::min(vertices, text.size() / 6));
  out.mesh.triangles.reserve(std::min(faces, text.size() / 8));

  for (std::size_t v = 0; v < vertices; ++v) {
    if (!lines.next(fields)) lines.fail(fmt::format("the file ends after {} of its {} vertices", v, vertices));
    if (fields.size() < 3) lines.fail(fmt::format("vertex {} has {} coordinates (3 needed)", v, fields.size()));
    glm::vec3 position;
    for (int axis = 0; axis < 3; ++axis) {
      position[axis] = lines.real(fields[axis], fmt::format("vertex {} {} coordinate", v, "xyz"[axis]));
    }
    out.mesh.positions.push_back(position);
  }
  std::vector<std::uint32_t> corners;
  for (std::size_t f = 0; f < faces; ++f) {
    if (!lines.next(fields)) lines.fail(fmt::format("the file ends after {} of its {} faces", f, faces));
    const auto count = static_cast<std::size_t>(
        lines.integer(fields[0], fmt::format("face {} corner count", f), 0, std::int64_t{1} << 20));
    if (count < 3) lines.fail(fmt::format("face {} has {} corners (at least 3 needed)", f, count));
    if (fields.size() < count + 1) {
      lines.fail(fmt::format("face {} has {} corners but the line lists {}", f, count, fields.size() - 1));
    }
    corners.clear();
    for (std::size_t k = 0; k < count; ++k) {
      const std::int64_t index = lines.integer(fields[k + 1], fmt::format("face {} corner {}", f, k), 0, kMaxVertices);
      if (static_cast<std::size_t>(index) >= vertices) {
        lines.fail(fmt::format("face {} references vertex {} but there are only {} vertices", f, index, vertices));
      }
      corners.push_back(static_cast<std::uint32_t>(index));
    }
    add_polygon(out, corners);  // colour fields after the corners are not read
  }
}

}  // namespace wavetrace
