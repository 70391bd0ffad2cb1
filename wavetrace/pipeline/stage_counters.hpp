// What each stage did: rays in, rays out, busy seconds; lock-free, updated once per batch.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "wavetrace/memory/cache_simulator.hpp"
#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/memory/ray_spill.hpp"
#include "wavetrace/memory/simulated_pager.hpp"

namespace wavetrace {

struct PagerStats {
  std::size_t page_bytes = 0;
  std::size_t budget_bytes = 0;
  PagerCounters counters;
};

struct DiskStats {
  PageMapping mapping = PageMapping::memfd;
  std::size_t frames = 0;  // pages of the pool held in frames (FilePager::use_frames); 0: none
  std::size_t page_bytes = 0;
  std::size_t budget_bytes = 0;
  // For trace, its look-ahead's reads included (faults, bytes, read seconds, by part); the
  // wait seconds are the stage's own threads'.
  DiskCounters counters;
  std::uint64_t prefetched = 0;     // pages the look-ahead read (trace only)
  std::uint64_t prefetch_hits = 0;  // of those, pages trace read before they were evicted
  std::size_t reads_in_flight_max = 0;  // the pager's, over every stage
  // Faults by part of the file (a world's top tree, chunk nodes, leaf records...), "other"
  // last: where the reads go.
  std::vector<std::pair<std::string, std::uint64_t>> faults_by_part;
  // Windows of consecutive traced rays and the distinct pages they touched (trace only).
  RayWindowCounters ray_windows;
  double pages_per_window() const {
    return ray_windows.windows ? double(ray_windows.distinct_pages) / double(ray_windows.windows) : 0.0;
  }
};

struct CacheStats {
  CacheGeometry geometry;
  CacheCounters counters;
};

struct StageStats {
  std::string name;
  std::uint64_t rays_in = 0;
  std::uint64_t rays_out = 0;
  std::uint64_t batches = 0;
  double seconds = 0.0;  // thread-seconds spent inside the stage, summed over threads
  // Rays in per busy thread-second: the stage's throughput on one core.
  double mrays_per_s() const { return seconds > 0.0 ? double(rays_in) / seconds * 1e-6 : 0.0; }
  // Simulated memory traffic of the stage's accelerator reads, when observed.
  std::optional<PagerStats> pager;
  std::optional<CacheStats> cache;
  // Real paging of a world file (memory.backing = file), measured.
  std::optional<DiskStats> disk;
  // A disk ray buffer's runs (zsort with reorder.buffer = disk), measured.
  std::optional<SpillCounters> spill;
};

class StageCounters {
 public:
  explicit StageCounters(std::string name) : name_(std::move(name)) {}
  void record(std::uint64_t rays_in, std::uint64_t rays_out, std::uint64_t nanoseconds) {
    rays_in_.fetch_add(rays_in, std::memory_order_relaxed);
    rays_out_.fetch_add(rays_out, std::memory_order_relaxed);
    batches_.fetch_add(1, std::memory_order_relaxed);
    nanoseconds_.fetch_add(nanoseconds, std::memory_order_relaxed);
  }
  std::uint64_t rays_in() const { return rays_in_.load(std::memory_order_relaxed); }
  StageStats snapshot() const;

 private:
  std::string name_;
  std::atomic<std::uint64_t> rays_in_{0}, rays_out_{0}, batches_{0}, nanoseconds_{0};
};

}  // namespace wavetrace
