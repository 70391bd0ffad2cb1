// The stage objects a plan's chain names, built over a world and a film, in chain order.
#pragma once

#include <memory>
#include <vector>

#include "stages/film.hpp"
#include "stages/hit_rates.hpp"
#include "stages/memory_observation.hpp"
#include "stages/render_plan.hpp"
#include "stages/stage.hpp"
#include "stages/trace.hpp"
#include "stages/world.hpp"
#include "stages/zsort.hpp"

namespace wavetrace {

// Owns the stage objects a plan names, in chain order (generate excluded).
class StageChain {
 public:
  StageChain(const RenderPlan& plan, const World& world, Film& film, const MemoryObservers* observers = nullptr);
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
