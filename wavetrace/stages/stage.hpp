// The stage contract: a stage is a function of a batch and the read-only world, so any batch
// can run on any thread. A plain stage keeps no state between batches beyond its
// configuration and its lock-free counters; a buffering stage (buffering_stage.hpp) also holds
// the batches it has taken until it flushes them, and its node runs one call at a time.
#pragma once

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

class Stage {
 public:
  virtual ~Stage() = default;
  virtual std::string name() const = 0;
  // Owns `batch` on entry; must emit or release it (and any batch it acquires).
  virtual void process(Batch* batch, StageOutput& out) const = 0;
};

}  // namespace wavetrace
