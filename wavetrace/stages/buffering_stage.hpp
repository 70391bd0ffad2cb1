// A stage that holds rays across batches: zsort's sorting buffer, repack's open batch. Its
// pipeline node (make_buffering_node) runs one call at a time, and flushes it when every
// ray alive in the graph is waiting in it, since then nothing else will arrive.
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
};

}  // namespace wavetrace
