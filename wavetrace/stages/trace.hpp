// trace: closest hit for camera and bounce rays, any hit for shadow rays, on the main accelerator.
#pragma once

#include <atomic>
#include <cstdint>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/scene/material_runs.hpp"
#include "wavetrace/stages/hit_rates.hpp"
#include "wavetrace/stages/stage.hpp"

namespace wavetrace {

// Rays and busy nanoseconds by query kind: closest hit (camera and bounce rays) apart from
// any hit (shadow rays), so reordering's effect on each shows.
struct TraceTimes {
  std::atomic<std::uint64_t> closest_rays{0}, closest_nanoseconds{0};
  std::atomic<std::uint64_t> any_rays{0}, any_nanoseconds{0};
  double closest_mrays_per_s() const { return rate(closest_rays, closest_nanoseconds); }
  double any_mrays_per_s() const { return rate(any_rays, any_nanoseconds); }

 private:
  static double rate(const std::atomic<std::uint64_t>& rays, const std::atomic<std::uint64_t>& nanoseconds) {
    return nanoseconds.load() ? double(rays.load()) / double(nanoseconds.load()) * 1e3 : 0.0;
  }
};

// What a trace stage may count besides its own rays and seconds; each optional.
struct TraceInstruments {
  HitRateCounters* hit_rates = nullptr;        // hits per depth of closest-hit rays
  const MemoryObservers* observers = nullptr;  // see every traversal read, if the accelerator can be probed
  TraceTimes* times = nullptr;                 // seconds by query kind
};

// Besides the accelerator's hits (point and normal included), writes each closest hit's
// material from `materials`, so that shade and spawn never read the mesh.
class TraceStage final : public Stage {
 public:
  // `look_ahead`: with a world paged from a file (an observer with a file pager), how many of
  // the sorted batches queued for trace its look-ahead reads the pages of, on how many
  // threads; else unused.
  TraceStage(const Accelerator& accelerator, const MaterialRuns& materials, const TraceInstruments& instruments = {},
             LookAhead look_ahead = {})
      : accelerator_(accelerator), materials_(materials), instruments_(instruments) {
    if (instruments_.observers != nullptr && !(instruments_.observers->any() && accelerator.probed())) {
      instruments_.observers = nullptr;
    }
    if (instruments_.observers != nullptr && instruments_.observers->file_pager != nullptr) {
      look_ahead_ = look_ahead;
      look_ahead_observers_.file_pager = instruments_.observers->file_pager;
    }
  }
  std::string name() const override { return "trace"; }
  void process(Batch* batch, StageOutput& out) const override;

  // The look-ahead traces every kLookAheadStride-th ray of a queued batch on the copy, its
  // hits thrown away: its reads load the pages trace will read (the sorted neighbours of a
  // ray share its pages), counted to the pager's look-ahead client.
  LookAhead look_ahead_plan() const override { return look_ahead_; }
  void copy_ahead(const Batch& upcoming, Batch& copy) const override;
  void look_ahead(Batch& copy) const override;
  static constexpr std::uint32_t kLookAheadStride = 4;

  // Traces `range` of `batch`, whose rays are all of one kind. `probe` sees every read (null:
  // unobserved), and observed runs count their windows of consecutive rays.
  void trace_run(Batch& batch, RayRange range, RecordingProbe* probe = nullptr) const;
  // The megakernel's call: the batch's one ray, its reads seen by `probe` (null: unobserved),
  // whose windows of consecutive rays the caller closes.
  void trace_one_ray(Batch& batch, RecordingProbe* probe) const { trace_window(batch, {0, 1}, probe); }
  // What sees the reads of trace_run's walks, when they are observed ([memory]); else null.
  const MemoryObservers* observers() const { return instruments_.observers; }

  // Observed runs are traced this many rays at a time, the window in which the pager
  // counts the distinct pages consecutive rays touch (`disk.pages_per_1000_rays`).
  static constexpr std::uint32_t kRayWindow = 1000;

 private:
  void trace_window(Batch& batch, RayRange range, RecordingProbe* probe) const;

  const Accelerator& accelerator_;
  const MaterialRuns& materials_;
  TraceInstruments instruments_;
  LookAhead look_ahead_;
  MemoryObservers look_ahead_observers_;  // the file pager alone: no simulated pager or cache counts the look
};

}  // namespace wavetrace
