// trace: closest hit for camera and bounce rays, any hit for shadow rays, on the main accelerator.
#pragma once

#include "accel/accelerator.hpp"
#include "stages/stage.hpp"

namespace wavetrace {

class TraceStage final : public Stage {
 public:
  explicit TraceStage(const Accelerator& accelerator) : accelerator_(accelerator) {}
  std::string name() const override { return "trace"; }
  void process(Batch* batch, StageOutput& out) const override;

 private:
  const Accelerator& accelerator_;
};

}  // namespace wavetrace
