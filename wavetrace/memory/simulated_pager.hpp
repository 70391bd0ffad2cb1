// A simulated out-of-core memory pool, as in the reordering paper (§5): the world's bytes
// cut into fixed-size pages, an LRU pool of pages under a byte budget, and the I/O time the
// faults would cost on a given device. Nothing is really paged: reads are observed and counted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "wavetrace/memory/memory_budget.hpp"

namespace wavetrace {

// The simulated device: each fault costs latency + page bytes / bandwidth.
struct IoModel {
  std::string name;
  double latency_seconds = 0.0;
  double bytes_per_second = 0.0;
  bool operator==(const IoModel&) const = default;
};
// "disk": the paper's disk, 101 MB/s read, with 8 ms of seek and rotation (a 7200 rpm drive;
// the paper gives only the bandwidth). "nvme": a modern NVMe SSD, 3.5 GB/s, 80 us per read.
// Throws std::invalid_argument naming the known presets.
IoModel io_preset(std::string_view name);

struct PagerCounters {
  std::uint64_t accesses = 0;     // reads reported by probes
  std::uint64_t faults = 0;       // pages loaded into the pool
  std::uint64_t bytes_loaded = 0;
  double simulated_io_seconds = 0.0;
};

class SimulatedPager {
 public:
  // Spans may come in any order and must not overlap. At least one resident page is kept
  // whatever the budget. `clients` counters are kept apart (one per stage that reads).
  SimulatedPager(std::vector<std::span<const std::byte>> spans, std::size_t page_bytes, const MemoryBudget& budget,
        IoModel io, std::size_t clients = 1);

  static constexpr std::uint32_t kNoPage = 0xFFFFFFFFu;

  // The global page holding `address`, or kNoPage outside every span. Lock-free.
  std::uint32_t page_of(const void* address) const;
  // Marks the page most recently used, loading it (and evicting the least recently used
  // page if the pool is full) when it is not resident. Thread-safe.
  void touch(std::uint32_t page, std::size_t client);
  // Adds reads that needed no touch (their page was the caller's last): counted only.
  void add_accesses(std::uint64_t accesses, std::size_t client);

  PagerCounters counters(std::size_t client) const;
  PagerCounters total() const;

  std::size_t page_bytes() const { return page_bytes_; }
  std::size_t budget_bytes() const { return capacity_pages_ * page_bytes_; }
  std::size_t budget_pages() const { return capacity_pages_; }
  std::size_t world_bytes() const { return world_bytes_; }
  std::size_t page_count() const { return page_size_.size(); }
  const IoModel& io() const { return io_; }
  std::uint64_t outside_accesses() const;  // reads outside every span: a probe bug if not 0

 private:
  struct Region {
    std::uintptr_t begin = 0, end = 0;
    std::uint32_t first_page = 0;
  };
  struct alignas(64) ClientCounters {
    std::uint64_t accesses = 0, faults = 0, bytes_loaded = 0;
  };

  void unlink(std::uint32_t page);
  void push_front(std::uint32_t page);

  std::vector<Region> regions_;  // sorted by address
  std::size_t page_bytes_;
  unsigned page_shift_;
  std::size_t world_bytes_ = 0;
  std::size_t capacity_pages_;
  IoModel io_;

  mutable std::mutex mutex_;
  std::vector<std::uint32_t> page_size_;  // bytes of each page (a span's last page may be short)
  std::vector<std::uint32_t> previous_, next_;  // the LRU list, most recent at head_
  std::vector<std::uint8_t> resident_;
  std::uint32_t head_ = kNoPage, tail_ = kNoPage;
  std::size_t resident_count_ = 0;
  std::vector<ClientCounters> clients_;
  std::uint64_t outside_ = 0;
};

}  // namespace wavetrace
