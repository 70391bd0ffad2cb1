// spawn for photon mapping's camera pass: from a camera path's diffuse hit, the path tracer's
// light sample and photon.gather_rays cosine-weighted gathering rays (each weighing 1/n of
// the bounce); a gathering ray that meets a mirror or glass goes on specularly, still a
// gathering ray; a camera path's specular bounces are the path tracer's. Gathering rays fill
// batches of their own, as many as they need.
#pragma once

#include "wavetrace/stages/path_rules.hpp"
#include "wavetrace/stages/spawn.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

class GatherSpawnStage final : public Stage {
 public:
  // At most kMaxGatherRays a hit: each takes two of the 256 draw dimensions of its path.
  static constexpr std::uint32_t kMaxGatherRays = 128;
  GatherSpawnStage(const World& world, const PathRules& rules, std::uint32_t gather_rays);
  std::string name() const override { return "spawn"; }
  void process(Batch* batch, StageOutput& out) const override;
  // A diffuse hit's gathering rays and light sample; a specular hit's one bounce.
  static constexpr std::size_t rays_out_per_ray(std::uint32_t gather_rays) { return std::size_t{gather_rays} + 1; }
  std::size_t rays_out_per_ray() const override { return rays_out_per_ray(gather_rays_); }

 private:
  const World& world_;
  PathRules rules_;
  std::uint32_t gather_rays_;
  SpawnStage path_;
};

}  // namespace wavetrace
