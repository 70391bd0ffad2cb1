// The ASCII PLY reader of mesh_readers.hpp.
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "wavetrace/scene/mesh_readers.hpp"
#include "wavetrace/scene/ply_header.hpp"
#include "wavetrace/scene/text_lines.hpp"

namespace wavetrace {

void read_text_ply(std::string_view text, const std::string& path, LoadedMesh& out) {
  const PlyHeader header = parse_ply_header(text, path);
  if (header.format != PlyFormat::ascii) throw SceneError(fmt::format("{}: a binary PLY file, not ASCII", path));
  constexpr std::int64_t kMaxIndex = std::numeric_limits<std::uint32_t>::max();
  const std::uint64_t vertices = header.elements[header.vertex_element].count;
  if (vertices > static_cast<std::uint64_t>(kMaxIndex)) {
    throw SceneError(fmt::format("{}: {} vertices, beyond 32-bit indices", path, vertices));
  }
  const std::string_view body = text.substr(header.body_offset);
  // The counts are untrusted: reserve no more than the body could hold ("0 0 0\n" per vertex).
  out.mesh.positions.reserve(std::min<std::uint64_t>(vertices, body.size() / 6));
  // Faces may come before the vertices: their indices are checked against the header's count.
  TextLines lines(body, path, '\0', header.lines + 1);
  std::vector<std::string_view> fields;
  std::vector<std::uint32_t> corners;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    const bool is_vertex = e == header.vertex_element, is_face = e == header.face_element;
    for (std::uint64_t r = 0; r < element.count; ++r) {
      if (!lines.next(fields)) {
        lines.fail(fmt::format("the file ends after {} of its {} '{}' records", r, element.count, element.name));
      }
      if (!is_vertex && !is_face) continue;  // other elements: one record per line, unread
      std::size_t at = 0;
      const auto field = [&](std::string_view what) {
        if (at == fields.size()) lines.fail(fmt::format("{} {} has no {}", element.name, r, what));
        return fields[at++];
      };
      glm::vec3 position(0.0f);
      for (const PlyProperty& property : element.properties) {
        if (is_vertex) {
          const std::string_view value = field(property.name);
          for (int axis = 0; axis < 3; ++axis) {
            if (property.name == std::string_view("xyz" + axis, 1)) {
              position[axis] = lines.real(value, fmt::format("vertex {} {} coordinate", r, property.name));
            }
          }
        } else if (property.list) {
          const auto count = static_cast<std::size_t>(
              lines.integer(field("corner count"), fmt::format("face {} corner count", r), 0, std::int64_t{1} << 20));
          if (count < 3) lines.fail(fmt::format("face {} has {} corners (at least 3 needed)", r, count));
          corners.clear();
          for (std::size_t k = 0; k < count; ++k) {
            const std::int64_t index =
                lines.integer(field(fmt::format("corner {}", k)), fmt::format("face {} corner {}", r, k), 0, kMaxIndex);
            if (static_cast<std::uint64_t>(index) >= vertices) {
              lines.fail(fmt::format("face {} references vertex {} but there are only {} vertices", r, index, vertices));
            }
            corners.push_back(static_cast<std::uint32_t>(index));
          }
          add_polygon(out, corners);
        } else {
          field(property.name);  // a face scalar (a colour, a flag): present, not read
        }
      }
      if (at != fields.size()) {
        lines.fail(fmt::format("{} {} has {} fields, more than its properties give", element.name, r, fields.size()));
      }
      if (is_vertex) out.mesh.positions.push_back(position);
    }
  }
}

}  // namespace wavetrace
