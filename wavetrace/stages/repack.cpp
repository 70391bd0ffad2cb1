// Small batches copied into open batches (one per ray kind), each emitted when it fills.
#include "wavetrace/stages/repack.hpp"

namespace wavetrace {

std::size_t RepackStage::take(Batch* batch, StageOutput& out) const {
  const std::size_t count = batch->rays.count;
  if (count >= min_rays_) {
    out.emit(batch);
    return count;
  }
  std::size_t emitted = 0;
  for (std::size_t i = 0; i < count; ++i) {
    Batch*& open = open_[std::size_t(batch->rays.kind[i]) % kKinds];
    if (open == nullptr) open = out.acquire();
    RayBatch& rays = open->rays;
    rays.copy_ray(rays.count++, batch->rays, i);
    if (rays.count == rays.capacity()) {
      emitted += rays.count;
      out.emit(open);
      open = nullptr;
    }
  }
  out.release(batch);
  std::size_t held = 0;
  for (const Batch* open : open_) held += open != nullptr ? open->rays.count : 0;
  buffered_rays_.store(held, std::memory_order_seq_cst);
  return emitted;
}

std::size_t RepackStage::flush(StageOutput& out) const {
  std::size_t emitted = 0;
  for (Batch*& open : open_) {
    if (open == nullptr) continue;
    emitted += open->rays.count;
    out.emit(open);
    open = nullptr;
  }
  buffered_rays_.store(0, std::memory_order_seq_cst);
  return emitted;
}

}  // namespace wavetrace
