// The STL reader of mesh_readers.hpp: binary or ASCII, with corners at one position welded.
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include <fmt/format.h>

#include "wavetrace/scene/mesh_readers.hpp"
#include "wavetrace/scene/text_lines.hpp"

namespace wavetrace {
namespace {

constexpr std::size_t kBinaryHeaderBytes = 84;   // 80 bytes of anything, then the uint32 count
constexpr std::size_t kBinaryTriangleBytes = 50;  // normal, 3 corners (12 floats), uint16 attribute

// Gives each distinct position one vertex index, keyed on its bits (after -0 becomes +0).
class Welder {
 public:
  explicit Welder(LoadedMesh& out) : out_(out) {}
  std::uint32_t vertex(glm::vec3 position) {
    position += glm::vec3(0.0f);  // -0 + 0 = +0
    const std::array<std::uint32_t, 3> key = {std::bit_cast<std::uint32_t>(position.x),
                                              std::bit_cast<std::uint32_t>(position.y),
                                              std::bit_cast<std::uint32_t>(position.z)};
    const auto [slot, added] = index_of_.try_emplace(key, static_cast<std::uint32_t>(out_.mesh.positions.size()));
    if (added) out_.mesh.positions.push_back(position);
    return slot->second;
  }

 private:
  struct KeyHash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& key) const {
      return (std::size_t{key[0]} * 0x9E3779B97F4A7C15ull) ^ (std::size_t{key[1]} * 0xC2B2AE3D27D4EB4Full) ^
             (std::size_t{key[2]} * 0x165667B19E3779F9ull);
    }
  };
  LoadedMesh& out_;
  std::unordered_map<std::array<std::uint32_t, 3>, std::uint32_t, KeyHash> index_of_;
};

void read_binary_stl(std::string_view bytes, std::size_t triangles, const std::string& path, LoadedMesh& out) {
  Welder welder(out);
  out.mesh.triangles.reserve(triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    const std::size_t offset = kBinaryHeaderBytes + t * kBinaryTriangleBytes;
    float corners[9];
    std::memcpy(corners, bytes.data() + offset + 12, sizeof corners);  // the normal is not read
    std::array<std::uint32_t, 3> triangle;
    for (int c = 0; c < 3; ++c) {
      const glm::vec3 position(corners[3 * c], corners[3 * c + 1], corners[3 * c + 2]);
      if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z)) {
        throw SceneError(fmt::format("{}: triangle {} (byte {}): corner {} has a non-finite coordinate ({}, {}, {})", path,
                                     t, offset, c, position.x, position.y, position.z));
      }
      triangle[c] = welder.vertex(position);
    }
    add_polygon(out, triangle);
  }
}

void read_text_stl(std::string_view text, const std::string& path, LoadedMesh& out) {
  Welder welder(out);
  TextLines lines(text, path, '\0');
  std::vector<std::string_view> fields;
  std::vector<std::uint32_t> corners;
  std::size_t facets = 0;
  bool in_facet = false;
  while (lines.next(fields)) {
    const std::string_view keyword = fields[0];
    if (keyword == "facet") {
      if (in_facet) lines.fail(fmt::format("facet {} starts before facet {} ends", facets + 1, facets));
      in_facet = true;
      corners.clear();
    } else if (keyword == "vertex") {
      if (!in_facet) lines.fail("a vertex outside a facet");
      if (fields.size() != 4) lines.fail(fmt::format("facet {} vertex has {} coordinates (3 needed)", facets, fields.size() - 1));
      if (corners.size() == 3) lines.fail(fmt::format("facet {} has more than 3 vertices (STL facets are triangles)", facets));
      glm::vec3 position;
      for (int axis = 0; axis < 3; ++axis) {
        position[axis] = lines.real(fields[axis + 1], fmt::format("facet {} vertex {} {} coordinate", facets, corners.size(),
                                                                  "xyz"[axis]));
      }
      corners.push_back(welder.vertex(position));
    } else if (keyword == "endfacet") {
      if (!in_facet) lines.fail("endfacet without a facet");
      if (corners.size() != 3) lines.fail(fmt::format("facet {} has {} vertices (STL facets are triangles)", facets, corners.size()));
      add_polygon(out, corners);
      in_facet = false;
      ++facets;
    } else if (keyword != "solid" && keyword != "endsolid" && keyword != "outer" && keyword != "endloop") {
      lines.fail(fmt::format("unknown STL keyword '{}'", keyword.substr(0, 20)));
    }
  }
  if (in_facet) lines.fail(fmt::format("the file ends inside facet {}", facets));
}

}  // namespace

void read_stl(std::string_view bytes, const std::string& path, LoadedMesh& out) {
  // Binary files may begin with "solid" too, so the size decides first.
  if (bytes.size() >= kBinaryHeaderBytes) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (bytes.size() == kBinaryHeaderBytes + std::size_t{count} * kBinaryTriangleBytes) {
      read_binary_stl(bytes, count, path, out);
      return;
    }
  }
  const std::size_t start = bytes.find_first_not_of(" \t\r\n");
  if (start != std::string_view::npos && bytes.substr(start).starts_with("solid")) {
    read_text_stl(bytes, path, out);
    return;
  }
  throw SceneError(fmt::format(
      "{}: not an STL file ({} bytes: not 84 + 50 x its triangle count, as binary STL is, and not starting with "
      "'solid', as ASCII STL does)",
      path, bytes.size()));
}

}  // namespace wavetrace
