// Splits a batch into runs of one ray kind and hands each run to the accelerator: shadow
// rays to any hit, camera rays to the coherent (packet) query, bounce rays to closest hit.
#include "wavetrace/stages/trace.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include <tbb/task_arena.h>

#include "wavetrace/stages/observed_stage.hpp"

namespace wavetrace {

namespace {

// Calls visit(kind, range) for each run of consecutive rays of one kind, in order.
template <typename Visit>
void for_each_run_of_one_kind(const RayBatch& rays, Visit&& visit) {
  const auto count = static_cast<std::uint32_t>(rays.count);
  for (std::uint32_t begin = 0, end = 0; begin < count; begin = end) {
    end = begin + 1;
    while (end < count && rays.kind[end] == rays.kind[begin]) ++end;
    visit(rays.kind[begin], RayRange{begin, end});
  }
}

}  // namespace

void TraceStage::process(Batch* batch, StageOutput& out) const {
  std::optional<RecordingProbe> probe;
  if (instruments_.observers != nullptr) {
    probe.emplace(*instruments_.observers, std::size_t(ObservedStage::trace),
                  std::size_t(tbb::this_task_arena::current_thread_index()));
    probe->count_ray_windows();
  }
  for_each_run_of_one_kind(batch->rays, [&](RayKind kind, RayRange run) {
    if (instruments_.times == nullptr) {
      trace_run(*batch, run, probe ? &*probe : nullptr);
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    trace_run(*batch, run, probe ? &*probe : nullptr);
    const auto nanoseconds = static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count());
    const bool shadow = kind == RayKind::shadow;
    (shadow ? instruments_.times->any_rays : instruments_.times->closest_rays).fetch_add(run.size());
    (shadow ? instruments_.times->any_nanoseconds : instruments_.times->closest_nanoseconds).fetch_add(nanoseconds);
  });
  out.emit(batch);
}

void TraceStage::copy_ahead(const Batch& upcoming, Batch& copy) const {
  const RayBatch& from = upcoming.rays;
  RayBatch& to = copy.rays;
  to.count = 0;
  for (std::size_t i = 0; i < from.count; i += kLookAheadStride) {
    if (!(from.flags[i] & ray_flags::alive)) continue;
    const std::size_t k = to.count++;
    to.set_geometry(k, {from.origin_x[i], from.origin_y[i], from.origin_z[i]},
                    {from.direction_x[i], from.direction_y[i], from.direction_z[i]}, from.tmin[i], from.tmax[i]);
    to.kind[k] = from.kind[i];
    to.flags[k] = ray_flags::alive;
  }
}

void TraceStage::look_ahead(Batch& copy) const {
  RecordingProbe probe(look_ahead_observers_, kLookAheadClient, 0);
  for_each_run_of_one_kind(copy.rays, [&](RayKind kind, RayRange run) {
    if (kind == RayKind::shadow) {
      accelerator_.intersect_any_probed(copy.rays, copy.hits, run, probe);
    } else {
      accelerator_.intersect_closest_probed(copy.rays, copy.hits, run, probe);
    }
  });
}

void TraceStage::trace_run(Batch& batch, RayRange range, RecordingProbe* probe) const {
  if (probe != nullptr) {
    // Observed, the run is traced in windows of consecutive rays, so the pager can count the
    // distinct pages each window touched (the same hits: each ray is traced on its own).
    for (std::uint32_t begin = range.begin; begin < range.end; begin += kRayWindow) {
      const std::uint32_t end = std::min(range.end, begin + kRayWindow);
      trace_window(batch, {begin, end}, probe);
      probe->end_ray_window(end - begin == kRayWindow);
    }
    return;
  }
  trace_window(batch, range, nullptr);
}

void TraceStage::trace_window(Batch& batch, RayRange range, RecordingProbe* probe) const {
  const RayBatch& rays = batch.rays;
  HitBatch& hits = batch.hits;
  const RayKind kind = rays.kind[range.begin];
  if (kind == RayKind::shadow) {
    if (probe != nullptr) {
      accelerator_.intersect_any_probed(rays, hits, range, *probe);
    } else {
      accelerator_.intersect_any(rays, hits, range);
    }
    return;
  }
  if (probe != nullptr) {
    accelerator_.intersect_closest_probed(rays, hits, range, *probe);
  } else if (kind == RayKind::camera) {
    accelerator_.intersect_coherent(rays, hits, range);  // packets where the accelerator has them
  } else {
    accelerator_.intersect_closest(rays, hits, range);
  }
  for (std::uint32_t i = range.begin; i < range.end; ++i) {
    if (hits.is_hit(i)) hits.material[i] = materials_.material(hits.primitive[i]);
  }
  if (instruments_.hit_rates != nullptr) instruments_.hit_rates->record(rays, hits, range);
}

}  // namespace wavetrace
