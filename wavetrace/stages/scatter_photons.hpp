// scatter_photons: the photon pass's shading. A photon that lands on a diffuse surface is
// left there (in the caustic map too if only mirrors and glass brought it); then, past
// Russian roulette by the surface's albedo, it bounces on, diffusely or specularly, keeping
// its flux per photon about constant. Photons that leave the scene end.
#pragma once

#include "wavetrace/stages/path_rules.hpp"
#include "wavetrace/stages/photon_deposits.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

class ScatterPhotonsStage final : public Stage {
 public:
  ScatterPhotonsStage(const World& world, PhotonDeposits& deposits, const PathRules& rules)
      : world_(world), deposits_(deposits), rules_(rules) {}
  std::string name() const override { return "scatter_photons"; }
  void process(Batch* batch, StageOutput& out) const override;

 private:
  const World& world_;
  PhotonDeposits& deposits_;
  PathRules rules_;
};

}  // namespace wavetrace
