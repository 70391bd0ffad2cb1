// The share of closest-hit rays (camera rays at depth 0, bounce rays after) that hit the
// scene, per path depth: counted by trace, reported in the stage table and the stats.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

struct DepthHitRate {
  int depth = 0;
  std::uint64_t rays = 0;
  std::uint64_t hits = 0;
  double rate() const { return rays ? double(hits) / double(rays) : 0.0; }
};

class HitRateCounters {
 public:
  static constexpr int kDepths = 65;  // depths 0..64, as render.max_depth allows

  // Counts the non-shadow rays of `range` and their hits; atomics once per call.
  void record(const RayBatch& rays, const HitBatch& hits, RayRange range);
  // Adds counts decided elsewhere (approx_hit's box misses).
  void add(int depth, std::uint64_t rays, std::uint64_t hits) {
    rays_[depth].fetch_add(rays, std::memory_order_relaxed);
    hits_[depth].fetch_add(hits, std::memory_order_relaxed);
  }
  // Every depth that saw a ray, in order.
  std::vector<DepthHitRate> snapshot() const;

 private:
  std::array<std::atomic<std::uint64_t>, kDepths> rays_{};
  std::array<std::atomic<std::uint64_t>, kDepths> hits_{};
};

}  // namespace wavetrace
