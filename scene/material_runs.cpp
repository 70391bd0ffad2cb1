// Run-length encoding of per-triangle materials.
#include "scene/material_runs.hpp"

#include <stdexcept>

namespace wavetrace {

MaterialRuns MaterialRuns::from_triangles(std::span<const std::uint32_t> material_of_triangle, std::size_t triangles) {
  MaterialRuns runs;
  if (material_of_triangle.empty()) {
    runs.append(0, 0);
    return runs;
  }
  for (std::size_t t = 0; t < triangles; ++t) runs.append(t, material_of_triangle[t]);
  return runs;
}

void MaterialRuns::append(std::uint64_t first, std::uint32_t material) {
  if (!first_.empty() && first < first_.back()) throw std::logic_error("material runs must be appended in order");
  if (!material_.empty() && material_.back() == material) return;
  if (!first_.empty() && first_.back() == first) {
    material_.back() = material;
    return;
  }
  first_.push_back(first);
  material_.push_back(material);
}

}  // namespace wavetrace
