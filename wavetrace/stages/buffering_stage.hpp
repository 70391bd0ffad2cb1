// A stage that holds rays across batches: zsort's sorting buffer, repack's open batch. Its
// pipeline node (make_buffering_node) runs one call at a time, and flushes it when every
// ray alive in the graph is waiting in it, since then nothing else will arrive. What such a
// stage keeps between calls (its held batches, its runs on disk) is touched only there.
#pragma once

#include <cstddef>

#include "wavetrace/stages/stage.hpp"

namespace wavetrace {

class BufferingStage : public Stage {
 public:
  // Takes `batch`, emitting through `out` whatever is ready; returns the rays emitted.
  virtual std::size_t take(Batch* batch, StageOutput& out) const = 0;
  // Emits everything held; returns the rays emitted.
  virtual std::size_t flush(StageOutput& out) const = 0;
  // Rays held now; read by the pipeline to decide that everything alive is waiting here.
  virtual std::size_t buffered_rays() const = 0;

  // A buffer with an on-disk part (zsort with reorder.buffer = disk). Rays on disk are alive
  // but take no memory, so the pipeline's flight budget counts all live rays but these.
  virtual std::size_t spilled_rays() const { return 0; }
  // After a flush that sorted runs on disk, the sorted stream is emitted a little at a time,
  // as the flight budget makes room: drain emits at least one batch and about `max_rays`.
  virtual bool draining() const { return false; }
  virtual std::size_t drain(StageOutput& out, std::size_t max_rays) const { return 0; }
};

}  // namespace wavetrace
