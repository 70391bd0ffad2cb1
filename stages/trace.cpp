// Splits a batch into runs of one ray kind and hands each run to the accelerator: shadow
// rays to any hit, camera rays to the coherent (packet) query, bounce rays to closest hit.
#include "stages/trace.hpp"

#include <chrono>
#include <optional>

#include <tbb/task_arena.h>

#include "stages/memory_observation.hpp"

namespace wavetrace {

void TraceStage::process(Batch* batch, StageOutput& out) const {
  const RayBatch& rays = batch->rays;
  std::optional<RecordingProbe> probe;
  if (instruments_.observers != nullptr) {
    probe.emplace(*instruments_.observers, std::size_t(ObservedStage::trace),
                  std::size_t(tbb::this_task_arena::current_thread_index()));
  }
  std::uint32_t begin = 0;
  const auto count = static_cast<std::uint32_t>(rays.count);
  while (begin < count) {
    const RayKind kind = rays.kind[begin];
    const bool shadow = kind == RayKind::shadow;
    std::uint32_t end = begin + 1;
    while (end < count && rays.kind[end] == kind) ++end;
    const auto start = std::chrono::steady_clock::now();
    if (shadow) {
      if (probe) {
        accelerator_.intersect_any_probed(rays, batch->hits, {begin, end}, *probe);
      } else {
        accelerator_.intersect_any(rays, batch->hits, {begin, end});
      }
    } else {
      if (probe) {
        accelerator_.intersect_closest_probed(rays, batch->hits, {begin, end}, *probe);
      } else if (kind == RayKind::camera) {
        accelerator_.intersect_coherent(rays, batch->hits, {begin, end});  // packets where the accelerator has them
      } else {
        accelerator_.intersect_closest(rays, batch->hits, {begin, end});
      }
    }
    if (instruments_.times != nullptr) {
      const auto nanoseconds = static_cast<std::uint64_t>(
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count());
      (shadow ? instruments_.times->any_rays : instruments_.times->closest_rays).fetch_add(end - begin);
      (shadow ? instruments_.times->any_nanoseconds : instruments_.times->closest_nanoseconds).fetch_add(nanoseconds);
    }
    if (!shadow) {
      HitBatch& hits = batch->hits;
      for (std::uint32_t i = begin; i < end; ++i) {
        if (hits.is_hit(i)) hits.material[i] = materials_.material(hits.primitive[i]);
      }
      if (instruments_.hit_rates != nullptr) instruments_.hit_rates->record(rays, hits, {begin, end});
    }
    begin = end;
  }
  out.emit(batch);
}

}  // namespace wavetrace
