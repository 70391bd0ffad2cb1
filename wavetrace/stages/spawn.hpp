// spawn: from each surviving diffuse hit, a shadow ray toward a light sample (carrying the
// light it would deliver) and, if the path continues, a cosine-weighted bounce ray; from a
// mirror or glass, only its specular ray. Shadow rays go out in a batch of their own.
#pragma once

#include "wavetrace/kernels/specular.hpp"
#include "wavetrace/stages/path_rules.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

class SpawnStage final : public Stage {
 public:
  SpawnStage(const World& world, const PathRules& rules) : world_(world), rules_(rules) {}
  std::string name() const override { return "spawn"; }
  void process(Batch* batch, StageOutput& out) const override;
  static constexpr std::size_t kRaysOutPerRay = 2;  // a bounce and a light sample
  std::size_t rays_out_per_ray() const override { return kRaysOutPerRay; }

  // Appends the rays spawned from the live rays of `range` of `batch` to `bounces` and
  // (when the scene has lights) `shadows`; the megakernel calls it for one ray.
  void spawn(const Batch& batch, RayRange range, RayBatch& bounces, RayBatch* shadows) const;

 private:
  const World& world_;
  PathRules rules_;
};

// Where light arriving along unit `incoming` leaves a mirror or glass whose unit `outward`
// normal faces its outside; glass draws its Fresnel choice from path `path` at `depth`.
SpecularScatter scatter_specular(const Material& material, const glm::vec3& incoming, const glm::vec3& outward,
                                 std::uint64_t path, std::uint32_t depth);

// The bounce of live ray `i` of `rays` off the mirror or glass it hit, appended to `bounces`
// as a ray of `kind`: its one direction (glass chooses reflection or refraction by Fresnel),
// its weight the path's times the tint (over the survival probability where Russian
// roulette applies), and no light sample.
void write_specular_bounce(const RayBatch& rays, const HitBatch& hits, std::size_t i, const Material& material,
                           const PathRules& rules, RayBatch& bounces, RayKind kind);

}  // namespace wavetrace
