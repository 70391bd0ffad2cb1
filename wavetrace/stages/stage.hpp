// The stage contract: a stage is a function of a batch and the read-only world, so any batch
// can run on any thread. A plain stage keeps no state between batches beyond its
// configuration and its lock-free counters; a buffering stage (buffering_stage.hpp) also holds
// the batches it has taken until it flushes them, and its node runs one call at a time.
#pragma once

#include <cstddef>
#include <string>

#include "wavetrace/memory/batch_pool.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

// Where a stage puts its results: the next stage, or back to the pool.
class StageOutput {
 public:
  virtual ~StageOutput() = default;
  virtual void emit(Batch* batch) = 0;       // pass on to the next stage
  virtual Batch* acquire() = 0;              // an empty batch for new rays
  virtual void release(Batch* batch) = 0;    // rays in it are finished
};

// How far and on how many threads a stage reads ahead of itself (Stage::look_ahead_plan).
struct LookAhead {
  std::size_t batches = 0;
  std::size_t threads = 1;
};

class Stage {
 public:
  virtual ~Stage() = default;
  virtual std::string name() const = 0;
  // Owns `batch` on entry; must emit or release it (and any batch it acquires).
  virtual void process(Batch* batch, StageOutput& out) const = 0;

  // The most rays alive after this stage for each ray that enters it (the ray itself, or the
  // rays it spawns in its place). The pipeline's sources leave room in the flight budget for
  // what each ray they emit may become, so that the budget bounds the rays alive at once.
  virtual std::size_t rays_out_per_ray() const { return 1; }

  // Reading ahead: a stage that takes a buffering stage's batches in their order (the
  // pipeline's ordered hand-off) may look at the first `batches` batches queued for it, on
  // `threads` threads of their own (each on the next batch none has seen), while the batches
  // before them are processed. A trace whose world is paged from disk reads their pages then,
  // so that its own reads find them loaded. `copy_ahead` runs while the queued batch cannot
  // change (copy what the look needs into `copy`); `look_ahead` then runs on the copy.
  // Neither may change what the stage computes. batches = 0: no look-ahead.
  virtual LookAhead look_ahead_plan() const { return {}; }
  virtual void copy_ahead(const Batch& /*upcoming*/, Batch& /*copy*/) const {}
  virtual void look_ahead(Batch& /*copy*/) const {}
};

}  // namespace wavetrace
