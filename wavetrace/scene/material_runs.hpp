// The material of every triangle as runs of consecutive triangle ids. Objects are contiguous
// in a flattened scene, so a scene of billions of triangles needs a handful of runs where a
// per-triangle index would cost 4 bytes a triangle; shading looks materials up here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace wavetrace {

class MaterialRuns {
 public:
  // Runs of a per-triangle list; an empty list is one run of material 0.
  static MaterialRuns from_triangles(std::span<const std::uint32_t> material_of_triangle, std::size_t triangles);
  // Runs as firsts() and materials() list them (a saved world's); throws std::invalid_argument
  // when the lists differ in length or the firsts decrease.
  static MaterialRuns from_runs(std::span<const std::uint64_t> firsts, std::span<const std::uint32_t> materials);
  std::span<const std::uint64_t> firsts() const { return first_; }
  std::span<const std::uint32_t> materials() const { return material_; }

  // Triangles from `first` on (until the next append) use `material`; first must not
  // decrease. Extends the last run when the material is the same.
  void append(std::uint64_t first, std::uint32_t material);

  // Binary search over the runs' starts; a triangle before the first run has material 0.
  std::uint32_t material(std::uint64_t triangle) const {
    std::size_t low = 0, high = first_.size();
    while (high - low > 1) {
      const std::size_t middle = (low + high) / 2;
      (first_[middle] <= triangle ? low : high) = middle;
    }
    return first_.empty() || first_[low] > triangle ? 0u : material_[low];
  }
  std::size_t run_count() const { return first_.size(); }
  std::size_t bytes() const { return first_.size() * (sizeof(std::uint64_t) + sizeof(std::uint32_t)); }

 private:
  std::vector<std::uint64_t> first_;
  std::vector<std::uint32_t> material_;
};

}  // namespace wavetrace
