// Stage names to stage objects.
#include "wavetrace/setup/stage_chain.hpp"

#include <stdexcept>

#include "wavetrace/stages/approx_hit.hpp"
#include "wavetrace/stages/gather_shade.hpp"
#include "wavetrace/stages/gather_spawn.hpp"
#include "wavetrace/stages/repack.hpp"
#include "wavetrace/stages/scatter_photons.hpp"
#include "wavetrace/stages/shade.hpp"
#include "wavetrace/stages/spawn.hpp"

namespace wavetrace {

StageChain::StageChain(const RenderPlan& plan, const World& world, Film* film, const MemoryObservers* observers,
                       ChainShading shading) {
  if ((film == nullptr) != (shading.deposits != nullptr)) {
    throw std::logic_error("a chain has a film, or else fills photon deposits");
  }
  const PathRules& rules = plan.rules;
  for (const std::string& name : plan.stages) {
    if (name == "generate") continue;
    if (name == "approx_hit") {
      if (world.proxy == nullptr) throw std::logic_error("approx_hit needs the world's proxy");
      owned_.push_back(std::make_unique<ApproxHitStage>(*world.proxy, film, world.scene.background, &hit_rates_, observers));
    }
    if (name == "zsort") {
      auto zsort = std::make_unique<ZSortStage>(plan.reorder, world.scene.bounds);
      zsort_ = zsort.get();
      owned_.push_back(std::move(zsort));
    }
    if (name == "repack") owned_.push_back(std::make_unique<RepackStage>(plan.pipeline.batch_size / 2));
    if (name == "trace") {
      owned_.push_back(std::make_unique<TraceStage>(world.accelerator, world.scene.material_runs,
                                                    TraceInstruments{&hit_rates_, observers, &trace_times_},
                                                    LookAhead{plan.memory.look_ahead_batches, plan.memory.look_ahead_threads}));
    }
    if (name == "shade") {
      if (shading.deposits != nullptr) {
        owned_.push_back(std::make_unique<ScatterPhotonsStage>(world, *shading.deposits, rules));
      } else if (shading.maps != nullptr) {
        owned_.push_back(std::make_unique<GatherShadeStage>(world, *film, rules, *shading.maps));
      } else {
        owned_.push_back(std::make_unique<ShadeStage>(world, *film, rules));
      }
    }
    if (name == "spawn") {
      // The photon pass's scatter bounces its photons itself: only the loop is left.
      if (shading.maps != nullptr) {
        owned_.push_back(std::make_unique<GatherSpawnStage>(world, rules, plan.photon.gather_rays));
      } else if (shading.deposits == nullptr) {
        owned_.push_back(std::make_unique<SpawnStage>(world, rules));
      }
      loops_ = true;
    }
  }
}

std::vector<const Stage*> StageChain::stages() const {
  std::vector<const Stage*> stages;
  for (const auto& stage : owned_) stages.push_back(stage.get());
  return stages;
}

}  // namespace wavetrace
