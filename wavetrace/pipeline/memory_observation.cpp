// memory.* keys to a pager and caches, and their counters into the stage statistics.
#include "wavetrace/pipeline/memory_observation.hpp"

#include <bit>
#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {

MemoryObservation::MemoryObservation(const MemoryPlan& plan, std::vector<std::span<const std::byte>> world,
                                     int threads, FilePager* file_pager, bool reads_through_frames)
    : file_pager_(file_pager) {
  if (file_pager_ != nullptr) {
    file_pager_->reset();
    file_pager_->use_frames(plan.page_frames && reads_through_frames);
    file_pager_->set_prefetch_client(kLookAheadClient);
    if (!plan.page_trace.empty()) {
      page_trace_ = std::make_unique<PageTrace>(plan.page_trace);
      file_pager_->set_page_trace(page_trace_.get());
    }
  }
  // Beside real paging the simulated pager is a cross-check that costs time in the measured
  // render (a lock per page change: room:8M at 24%, 13.9 s against 15.3 with it; 2.2 against
  // 5.9 with the whole world resident), so it runs there only when asked.
  if (plan.budget && (file_pager_ == nullptr || plan.simulate_beside_file)) {
    pager_ = std::make_unique<SimulatedPager>(std::move(world), plan.page_bytes, *plan.budget, plan.io, kObservedStageCount);
  }
  if (plan.cache) caches_ = std::make_unique<CacheBank>(*plan.cache, std::size_t(threads), kObservedStageCount);
  observers_ = {pager_.get(), caches_.get(), file_pager_};
}

MemoryObservation::~MemoryObservation() {
  if (page_trace_ != nullptr) file_pager_->set_page_trace(nullptr);
}

void MemoryObservation::report(std::vector<StageStats>& stages) const {
  if (page_trace_ != nullptr) page_trace_->flush();  // a full disk is an error naming the file, not a note at exit
  for (StageStats& stage : stages) {
    for (std::size_t client = 0; client < kObservedStageCount; ++client) {
      if (stage.name != to_string(ObservedStage(client))) continue;
      if (pager_) stage.pager = PagerStats{pager_->page_bytes(), pager_->budget_bytes(), pager_->counters(client)};
      if (caches_) stage.cache = CacheStats{caches_->geometry(), caches_->total(client)};
      if (file_pager_) {
        stage.disk.emplace();
        stage.disk->mapping = file_pager_->mapping();
        stage.disk->frames = file_pager_->frame_count();
        stage.disk->page_bytes = file_pager_->page_bytes();
        stage.disk->budget_bytes = file_pager_->budget_bytes();
        stage.disk->counters = file_pager_->counters(client);
        stage.disk->reads_in_flight_max = file_pager_->reads_in_flight_max();
        std::vector<std::uint64_t> faults = file_pager_->faults_by_part(client);
        if (ObservedStage(client) == ObservedStage::trace) {
          stage.disk->ray_windows = file_pager_->ray_windows();
          // The look-ahead reads for trace: its reads are trace's, read earlier.
          const DiskCounters ahead = file_pager_->counters(kLookAheadClient);
          stage.disk->counters.faults += ahead.faults;
          stage.disk->counters.unannounced += ahead.unannounced;
          stage.disk->counters.bytes_read += ahead.bytes_read;
          stage.disk->counters.read_seconds += ahead.read_seconds;
          stage.disk->prefetched = ahead.faults;
          stage.disk->prefetch_hits = file_pager_->prefetch_hits();
          const std::vector<std::uint64_t> ahead_faults = file_pager_->faults_by_part(kLookAheadClient);
          for (std::size_t part = 0; part < faults.size(); ++part) faults[part] += ahead_faults[part];
        }
        for (std::size_t part = 0; part < faults.size(); ++part) {
          if (faults[part] > 0) stage.disk->faults_by_part.emplace_back(file_pager_->part_names()[part], faults[part]);
        }
      }
    }
  }
}

}  // namespace wavetrace
