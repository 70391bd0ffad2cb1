// Extraction of a range of an in-memory mesh: its vertices in first-use order.
#include "wavetrace/scene/triangle_source.hpp"

#include <stdexcept>
#include <unordered_map>

#include <fmt/format.h>

namespace wavetrace {

TriangleMesh TriangleSource::triangles_with_materials(const std::vector<bool>& wanted) const {
  if (wanted.empty() || !wanted[0]) return {};
  TriangleMesh all = extract(0, triangle_count());
  all.material_of_triangle.assign(all.triangle_count(), 0);
  return all;
}

TriangleMesh MeshTriangleSource::extract(std::size_t first, std::size_t count) const {
  if (first > mesh_.triangle_count() || count > mesh_.triangle_count() - first) {
    throw std::out_of_range(fmt::format("mesh range [{}, {}) beyond its {} triangles", first, first + count,
                                        mesh_.triangle_count()));
  }
  TriangleMesh part;
  part.triangles.resize(count);
  std::unordered_map<std::uint32_t, std::uint32_t> local_of;
  local_of.reserve(count);
  for (std::size_t t = 0; t < count; ++t) {
    const glm::uvec3& corners = mesh_.triangles[first + t];
    for (int k = 0; k < 3; ++k) {
      const auto [slot, added] = local_of.emplace(corners[k], static_cast<std::uint32_t>(part.positions.size()));
      if (added) part.positions.push_back(mesh_.positions[corners[k]]);
      part.triangles[t][k] = slot->second;
    }
  }
  part.positions.reserve(part.positions.size() + 1);  // read slack, as validate_and_clean leaves
  return part;
}

}  // namespace wavetrace
