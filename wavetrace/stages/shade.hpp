// shade: light arriving along each traced ray goes into the film (sky for misses,
// emission seen by camera rays, unoccluded shadow rays' carried light), and Russian
// roulette decides which paths continue. Rays left alive go on to spawn.
#pragma once

#include "wavetrace/stages/film.hpp"
#include "wavetrace/stages/path_rules.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

class ShadeStage final : public Stage {
 public:
  ShadeStage(const World& world, Film& film, const PathRules& rules) : world_(world), film_(film), rules_(rules) {}
  std::string name() const override { return "shade"; }
  void process(Batch* batch, StageOutput& out) const override;

  // Shades `range` of `batch` (the megakernel calls it for one ray); returns how many of
  // its rays stay alive for spawn.
  std::size_t shade(Batch& batch, RayRange range) const;

 private:
  const World& world_;
  Film& film_;
  PathRules rules_;
};

}  // namespace wavetrace
