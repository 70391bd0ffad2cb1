// Snapshot of a stage's counters.
#include "stages/stage_counters.hpp"

namespace wavetrace {

StageStats StageCounters::snapshot() const {
  return {name_, rays_in_.load(), rays_out_.load(), batches_.load(), double(nanoseconds_.load()) * 1e-9};
}

}  // namespace wavetrace
