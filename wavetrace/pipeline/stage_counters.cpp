// Snapshot of a stage's counters.
#include "wavetrace/pipeline/stage_counters.hpp"

namespace wavetrace {

StageStats StageCounters::snapshot() const {
  StageStats stats;
  stats.name = name_;
  stats.rays_in = rays_in_.load();
  stats.rays_out = rays_out_.load();
  stats.batches = batches_.load();
  stats.seconds = double(nanoseconds_.load()) * 1e-9;
  return stats;
}

}  // namespace wavetrace
