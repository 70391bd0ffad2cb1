// Splits a batch into runs of one ray kind and hands each run to the accelerator.
#include "stages/trace.hpp"

namespace wavetrace {

void TraceStage::process(Batch* batch, StageOutput& out) const {
  const RayBatch& rays = batch->rays;
  std::uint32_t begin = 0;
  const auto count = static_cast<std::uint32_t>(rays.count);
  while (begin < count) {
    const bool shadow = rays.kind[begin] == RayKind::shadow;
    std::uint32_t end = begin + 1;
    while (end < count && (rays.kind[end] == RayKind::shadow) == shadow) ++end;
    if (shadow) {
      accelerator_.intersect_any(rays, batch->hits, {begin, end});
    } else {
      accelerator_.intersect_closest(rays, batch->hits, {begin, end});
      if (hit_rates_ != nullptr) hit_rates_->record(rays, batch->hits, {begin, end});
    }
    begin = end;
  }
  out.emit(batch);
}

}  // namespace wavetrace
