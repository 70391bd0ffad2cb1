// Per-depth hit counting: a local tally per batch, then one atomic add per depth seen.
#include "wavetrace/stages/hit_rates.hpp"

#include <algorithm>

namespace wavetrace {

void HitRateCounters::record(const RayBatch& rays, const HitBatch& hits, RayRange range) {
  std::array<std::uint32_t, kDepths> local_rays{}, local_hits{};
  int deepest = -1;
  for (std::uint32_t i = range.begin; i < range.end; ++i) {
    if (rays.kind[i] == RayKind::shadow) continue;
    const int depth = std::min<int>(rays.depth[i], kDepths - 1);
    ++local_rays[depth];
    local_hits[depth] += hits.is_hit(i);
    deepest = std::max(deepest, depth);
  }
  for (int depth = 0; depth <= deepest; ++depth) {
    if (local_rays[depth] == 0) continue;
    rays_[depth].fetch_add(local_rays[depth], std::memory_order_relaxed);
    hits_[depth].fetch_add(local_hits[depth], std::memory_order_relaxed);
  }
}

std::vector<DepthHitRate> HitRateCounters::snapshot() const {
  std::vector<DepthHitRate> rates;
  for (int depth = 0; depth < kDepths; ++depth) {
    const std::uint64_t rays = rays_[depth].load(std::memory_order_relaxed);
    if (rays > 0) rates.push_back({depth, rays, hits_[depth].load(std::memory_order_relaxed)});
  }
  return rates;
}

}  // namespace wavetrace
