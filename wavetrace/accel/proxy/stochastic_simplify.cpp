// A parallel filter with prefix offsets, so the kept triangles stay in input order.
#include "wavetrace/accel/proxy/stochastic_simplify.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "wavetrace/kernels/random.hpp"

namespace wavetrace {

TriangleMesh simplify_stochastically(const TriangleMesh& mesh, double share, std::size_t first_id) {
  share = std::clamp(share, 1e-9, 1.0);
  const auto threshold = static_cast<std::uint64_t>(share * 4294967296.0);
  const auto kept = [&](std::size_t local) {
    const std::size_t t = first_id + local;
    return (random_bits(std::uint32_t(t), std::uint32_t(t >> 32), 0, RandomPurpose::simplification) >> 32) < threshold;
  };
  std::vector<std::uint32_t> offset(mesh.triangle_count() + 1, 0);
  tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) { offset[t + 1] = kept(t) ? 1 : 0; });
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) offset[t + 1] += offset[t];
  const float scale = float(1.0 / std::sqrt(share));
  TriangleMesh result;
  const std::size_t count = offset.back();
  result.positions.resize(3 * count);
  result.triangles.resize(count);
  tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
    if (offset[t + 1] == offset[t]) return;
    const std::size_t slot = offset[t];
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::vec3 corners[3] = {mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]};
    const glm::vec3 centroid = (corners[0] + corners[1] + corners[2]) / 3.0f;
    for (int k = 0; k < 3; ++k) result.positions[3 * slot + k] = centroid + (corners[k] - centroid) * scale;
    const auto base = static_cast<std::uint32_t>(3 * slot);
    result.triangles[slot] = glm::uvec3(base, base + 1, base + 2);
  });
  return result;
}

}  // namespace wavetrace
