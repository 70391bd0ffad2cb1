// repack: batches that shrank on the way (deep bounces after Russian roulette and escapes,
// shadow rays of surfaces facing away from the lights) are gathered into full batches before
// trace, so trace and the stages after it see full batches; batches of at least `min_rays`
// pass through untouched. One open batch per ray kind (spawn's batches hold one kind each),
// so trace still gets runs of one query. A buffering stage: its node is serial.
#pragma once

#include <atomic>
#include <cstddef>

#include "wavetrace/stages/buffering_stage.hpp"

namespace wavetrace {

class RepackStage final : public BufferingStage {
 public:
  explicit RepackStage(std::size_t min_rays) : min_rays_(min_rays) {}
  std::string name() const override { return "repack"; }
  // Outside the pipeline's buffering node (a hand-wired chain): passes the batch on.
  void process(Batch* batch, StageOutput& out) const override { out.emit(batch); }

  std::size_t take(Batch* batch, StageOutput& out) const override;
  std::size_t flush(StageOutput& out) const override;
  std::size_t buffered_rays() const override { return buffered_rays_.load(std::memory_order_seq_cst); }

 private:
  std::size_t min_rays_;
  static constexpr std::size_t kKinds = 4;  // RayKind: camera, bounce, shadow, specular
  mutable Batch* open_[kKinds] = {};         // the batches being filled, by kind

  mutable std::atomic<std::size_t> buffered_rays_{0};
};

}  // namespace wavetrace
