// The choice among the stripifiers, by name, and the cut of strips to the format's length.
#include "wavetrace/accel/raystrips/stripify.hpp"

#include <algorithm>
#include <stdexcept>

namespace wavetrace {

StripifierKind parse_stripifier(const std::string& text) {
  if (text == "dual_path") return StripifierKind::dual_path;
  if (text == "openmesh") return StripifierKind::openmesh;
  if (text == "longest_of_three") return StripifierKind::longest_of_three;
  throw std::invalid_argument("unknown stripifier '" + text + "' (dual_path, openmesh, longest_of_three)");
}

std::string to_string(StripifierKind kind) {
  switch (kind) {
    case StripifierKind::dual_path: return "dual_path";
    case StripifierKind::openmesh: return "openmesh";
    case StripifierKind::longest_of_three: return "longest_of_three";
  }
  return "unknown";
}

std::vector<TriangleStrip> stripify(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                    StripifierKind kind, std::uint32_t max_triangles) {
  switch (kind) {
    case StripifierKind::dual_path: return stripify_dual_path(mesh, triangles, max_triangles);
    case StripifierKind::openmesh: return stripify_openmesh(mesh, triangles, max_triangles);
    case StripifierKind::longest_of_three: return stripify_longest_of_three(mesh, triangles, max_triangles);
  }
  throw std::invalid_argument("unknown stripifier");
}

std::vector<TriangleStrip> cut_long_strips(std::vector<TriangleStrip> strips, std::uint32_t max_triangles) {
  const auto only_swaps = [](const TriangleStrip& strip) {
    return std::all_of(strip.triangles.begin(), strip.triangles.end(), [](std::uint32_t t) { return t == kNoTriangle; });
  };
  if (std::none_of(strips.begin(), strips.end(), [&](const TriangleStrip& strip) {
        return strip.triangles.size() > max_triangles || only_swaps(strip);
      })) {
    return strips;  // the common case, without a second vector
  }
  std::vector<TriangleStrip> result;
  for (TriangleStrip& strip : strips) {
    if (strip.triangles.size() <= max_triangles) {
      result.push_back(std::move(strip));
      continue;
    }
    for (std::size_t first = 0; first < strip.triangles.size(); first += max_triangles) {
      const std::size_t count = std::min<std::size_t>(max_triangles, strip.triangles.size() - first);
      TriangleStrip piece;
      piece.vertices.assign(strip.vertices.begin() + first, strip.vertices.begin() + first + count + 2);
      piece.triangles.assign(strip.triangles.begin() + first, strip.triangles.begin() + first + count);
      result.push_back(std::move(piece));
    }
  }
  // A strip of swaps only (possible after cutting) adds nothing.
  std::erase_if(result, only_swaps);
  return result;
}

}  // namespace wavetrace
