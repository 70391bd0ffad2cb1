// The Wavefront OBJ reader of mesh_readers.hpp.
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "wavetrace/scene/mesh_readers.hpp"
#include "wavetrace/scene/text_lines.hpp"

namespace wavetrace {

void read_obj(std::string_view text, const std::string& path, LoadedMesh& out) {
  TextLines lines(text, path);
  std::vector<std::string_view> fields;
  std::vector<std::uint32_t> corners;
  constexpr std::int64_t kMaxIndex = std::numeric_limits<std::uint32_t>::max();
  std::size_t faces = 0;
  while (lines.next(fields)) {
    const std::string_view statement = fields[0];
    if (statement == "v") {
      const std::size_t v = out.mesh.positions.size();
      if (fields.size() < 4) lines.fail(fmt::format("vertex {} has {} coordinates (3 needed)", v + 1, fields.size() - 1));
      if (v == static_cast<std::size_t>(kMaxIndex)) lines.fail("more vertices than 32-bit indices can number");
      glm::vec3 position;
      for (int axis = 0; axis < 3; ++axis) {
        position[axis] = lines.real(fields[axis + 1], fmt::format("vertex {} {} coordinate", v + 1, "xyz"[axis]));
      }
      out.mesh.positions.push_back(position);
    } else if (statement == "f") {
      const std::size_t f = faces++;
      if (fields.size() < 4) lines.fail(fmt::format("face {} has {} corners (at least 3 needed)", f + 1, fields.size() - 1));
      corners.clear();
      const auto defined = static_cast<std::int64_t>(out.mesh.positions.size());
      for (std::size_t k = 1; k < fields.size(); ++k) {
        // Only the vertex of "v/t/n" is used; texture and normal indices are not read.
        const std::string_view vertex = fields[k].substr(0, fields[k].find('/'));
        const std::int64_t index = lines.integer(vertex, fmt::format("face {} corner {} vertex index", f + 1, k), -kMaxIndex, kMaxIndex);
        if (index == 0) lines.fail(fmt::format("face {} corner {} has vertex index 0 (OBJ counts from 1)", f + 1, k));
        const std::int64_t resolved = index > 0 ? index - 1 : defined + index;
        if (resolved < 0 || resolved >= defined) {
          lines.fail(fmt::format("face {} references vertex {} but {} vertices are defined before it", f + 1, index, defined));
        }
        corners.push_back(static_cast<std::uint32_t>(resolved));
      }
      add_polygon(out, corners);
    }
    // Every other statement (vt, vn, vp, g, o, s, usemtl, mtllib, l, p, curves) is skipped.
  }
}

}  // namespace wavetrace
