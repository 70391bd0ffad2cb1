// The [memory] section made real: a pager over the world's spans and a bank of simulated
// caches, observing the stages that query accelerators (trace; approx_hit with the proxy),
// each counted apart.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "wavetrace/memory/cache_simulator.hpp"
#include "wavetrace/memory/memory_probe.hpp"
#include "wavetrace/memory/page_trace.hpp"
#include "wavetrace/memory/simulated_pager.hpp"
#include "wavetrace/pipeline/stage_counters.hpp"
#include "wavetrace/stages/observed_stage.hpp"

namespace wavetrace {

struct MemoryPlan {
  std::optional<MemoryBudget> budget;  // no pager without one
  bool file_backing = false;           // memory.backing = file: a world file really paged under the budget
  bool copy_world = false;             // memory.backing = copy: a world file copied onto huge pages
  std::size_t page_bytes = std::size_t{4} << 20;
  PageMapping page_mapping = PageMapping::automatic;  // real paging: how resident pages appear (memory/page_mapping.hpp)
  bool page_frames = true;  // real paging: walks that can read pages in frames (FilePager::use_frames)
  // Real paging: sorted batches queued for trace whose pages its look-ahead reads first (0: none).
  std::size_t look_ahead_batches = 0;
  // Threads reading ahead, each on its own queued batch: reads in flight beside trace's own.
  std::size_t look_ahead_threads = 1;
  bool simulate_beside_file = false;  // real paging: also count the reads in the simulated pager
  std::string page_trace;             // real paging: the file each render's page touches go to (memory/page_trace.hpp)
  IoModel io = io_preset("disk");  // memory.io
  std::optional<CacheGeometry> cache;  // no cache simulation without one
  bool enabled() const { return budget.has_value() || cache.has_value(); }
  bool operator==(const MemoryPlan&) const = default;
};

class MemoryObservation {
 public:
  // `file_pager`: the real pager of a paged world file, or null; emptied here so each render
  // starts cold, and its pages kept in frames where the plan allows it and the world's walks
  // read through frames (`reads_through_frames`, Accelerator::reads_through_frames).
  MemoryObservation(const MemoryPlan& plan, std::vector<std::span<const std::byte>> world, int threads,
                    FilePager* file_pager = nullptr, bool reads_through_frames = false);
  ~MemoryObservation();  // detaches and writes the page trace
  MemoryObservation(const MemoryObservation&) = delete;
  MemoryObservation& operator=(const MemoryObservation&) = delete;
  const MemoryObservers& observers() const { return observers_; }
  // Fills the pager and cache objects of the observed stages in `stages`, and writes out the
  // page trace (throws naming its file when that fails).
  void report(std::vector<StageStats>& stages) const;

 private:
  std::unique_ptr<SimulatedPager> pager_;
  std::unique_ptr<CacheBank> caches_;
  FilePager* file_pager_ = nullptr;
  std::unique_ptr<PageTrace> page_trace_;
  MemoryObservers observers_;
};

}  // namespace wavetrace
