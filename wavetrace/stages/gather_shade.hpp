// shade for photon mapping's camera pass: what the path tracer's shade does (sky, emission
// seen by camera and specular rays, unoccluded shadow rays, mirrors and glass), and at a
// diffuse surface the photon maps' light. A camera path that meets one takes the caustic
// map's radiance there and goes on to spawn (light sample, gathering rays); a gathering ray
// (RayKind::bounce) takes the global map's radiance where it lands and ends.
#pragma once

#include "wavetrace/stages/film.hpp"
#include "wavetrace/stages/path_rules.hpp"
#include "wavetrace/stages/photon_map.hpp"
#include "wavetrace/stages/shade.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

class GatherShadeStage final : public Stage {
 public:
  GatherShadeStage(const World& world, Film& film, const PathRules& rules, const PhotonMaps& maps)
      : world_(world), film_(film), rules_(rules), maps_(maps), path_(world, film, rules) {}
  std::string name() const override { return "shade"; }
  void process(Batch* batch, StageOutput& out) const override;

 private:
  const World& world_;
  Film& film_;
  PathRules rules_;
  const PhotonMaps& maps_;
  ShadeStage path_;
};

}  // namespace wavetrace
