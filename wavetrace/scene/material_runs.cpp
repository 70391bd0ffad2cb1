// Run-length encoding of per-triangle materials.
#include "wavetrace/scene/material_runs.hpp"

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

MaterialRuns MaterialRuns::from_runs(std::span<const std::uint64_t> firsts, std::span<const std::uint32_t> materials) {
  if (firsts.size() != materials.size()) throw std::invalid_argument("material runs: as many firsts as materials needed");
  MaterialRuns runs;
  for (std::size_t i = 0; i < firsts.size(); ++i) {
    if (i > 0 && firsts[i] <= firsts[i - 1]) throw std::invalid_argument("material runs: firsts must increase");
    runs.first_.push_back(firsts[i]);
    runs.material_.push_back(materials[i]);
  }
  return runs;
}

}  // namespace wavetrace
