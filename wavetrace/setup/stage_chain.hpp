// The stage objects a plan's chain names, built over a world and a film (or, for the photon
// pass, the photon deposits), in chain order.
#pragma once

#include <memory>
#include <vector>

#include "wavetrace/stages/film.hpp"
#include "wavetrace/stages/hit_rates.hpp"
#include "wavetrace/stages/photon_deposits.hpp"
#include "wavetrace/stages/photon_map.hpp"
#include "wavetrace/pipeline/memory_observation.hpp"
#include "wavetrace/setup/render_plan.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/stages/trace.hpp"
#include "wavetrace/stages/world.hpp"
#include "wavetrace/stages/zsort.hpp"

namespace wavetrace {

// What a chain's shade and spawn are: the path tracer's (neither set), photon mapping's
// camera pass (reading `maps`, gather_shade.hpp and gather_spawn.hpp), or its photon pass
// (filling `deposits`: scatter_photons.hpp does both, and the chain has no film).
struct ChainShading {
  const PhotonMaps* maps = nullptr;
  PhotonDeposits* deposits = nullptr;
};

// Owns the stage objects a plan names, in chain order (generate excluded).
class StageChain {
 public:
  StageChain(const RenderPlan& plan, const World& world, Film* film, const MemoryObservers* observers = nullptr,
             ChainShading shading = {});
  std::vector<const Stage*> stages() const;
  bool loops() const { return loops_; }
  const HitRateCounters& hit_rates() const { return hit_rates_; }
  const ZSortStage* zsort() const { return zsort_; }
  const TraceTimes& trace_times() const { return trace_times_; }

 private:
  std::vector<std::unique_ptr<Stage>> owned_;
  HitRateCounters hit_rates_;
  TraceTimes trace_times_;
  const ZSortStage* zsort_ = nullptr;
  bool loops_ = false;
};

}  // namespace wavetrace
