// trace: closest hit for camera and bounce rays, any hit for shadow rays, on the main accelerator.
#pragma once

#include "accel/accelerator.hpp"
#include "stages/hit_rates.hpp"
#include "stages/stage.hpp"

namespace wavetrace {

class TraceStage final : public Stage {
 public:
  // `hit_rates`, if given, counts hits per depth of the closest-hit rays. `observers`, if
  // given and the accelerator can be probed, see every read of its traversal.
  explicit TraceStage(const Accelerator& accelerator, HitRateCounters* hit_rates = nullptr,
                      const MemoryObservers* observers = nullptr)
      : accelerator_(accelerator),
        hit_rates_(hit_rates),
        observers_(observers != nullptr && observers->any() && accelerator.probed() ? observers : nullptr) {}
  std::string name() const override { return "trace"; }
  void process(Batch* batch, StageOutput& out) const override;

 private:
  const Accelerator& accelerator_;
  HitRateCounters* hit_rates_;
  const MemoryObservers* observers_;
};

}  // namespace wavetrace
