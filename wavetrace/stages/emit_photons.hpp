// emit_photons: the photon pass's rays, leaving the area lights in proportion to their power,
// cosine-distributed about each light's normal, each carrying an equal share of the total
// flux. Photon i is a pure function of (i, seed), keyed like a path (photon_rules.hpp).
#pragma once

#include <algorithm>
#include <atomic>

#include "wavetrace/scene/lights.hpp"
#include "wavetrace/stages/ray_source.hpp"

namespace wavetrace {

class EmitPhotonsStage final : public RaySource {
 public:
  EmitPhotonsStage(const LightSampler& lights, std::uint64_t count, std::uint32_t seed);

  std::string name() const override { return "emit_photons"; }
  std::uint64_t total_rays() const override { return count_; }
  std::uint64_t generated() const override { return std::min(next_.load(std::memory_order_relaxed), count_); }
  bool exhausted() const override { return generated() >= count_; }
  Claim claim(std::size_t capacity) override;
  void fill_range(RayBatch& rays, const Claim& claimed) const override;

 private:
  const LightSampler& lights_;
  std::uint64_t count_;
  std::uint32_t sample_;
  std::atomic<std::uint64_t> next_{0};
};

}  // namespace wavetrace
