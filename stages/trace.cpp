// Splits a batch into runs of one ray kind and hands each run to the accelerator.
#include "stages/trace.hpp"

#include <optional>

#include <tbb/task_arena.h>

#include "stages/memory_observation.hpp"

namespace wavetrace {

void TraceStage::process(Batch* batch, StageOutput& out) const {
  const RayBatch& rays = batch->rays;
  std::optional<RecordingProbe> probe;
  if (observers_ != nullptr) {
    probe.emplace(*observers_, std::size_t(ObservedStage::trace), std::size_t(tbb::this_task_arena::current_thread_index()));
  }
  std::uint32_t begin = 0;
  const auto count = static_cast<std::uint32_t>(rays.count);
  while (begin < count) {
    const bool shadow = rays.kind[begin] == RayKind::shadow;
    std::uint32_t end = begin + 1;
    while (end < count && (rays.kind[end] == RayKind::shadow) == shadow) ++end;
    if (shadow) {
      if (probe) {
        accelerator_.intersect_any_probed(rays, batch->hits, {begin, end}, *probe);
      } else {
        accelerator_.intersect_any(rays, batch->hits, {begin, end});
      }
    } else {
      if (probe) {
        accelerator_.intersect_closest_probed(rays, batch->hits, {begin, end}, *probe);
      } else {
        accelerator_.intersect_closest(rays, batch->hits, {begin, end});
      }
      if (hit_rates_ != nullptr) hit_rates_->record(rays, batch->hits, {begin, end});
    }
    begin = end;
  }
  out.emit(batch);
}

}  // namespace wavetrace
