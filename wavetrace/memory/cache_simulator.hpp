// A set-associative cache with LRU replacement, simulated over the addresses probes report:
// the paper's 6 MB 24-way L2, or this machine's L1d and L2. One instance stands for one
// core's cache; a CacheBank keeps one per worker thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace wavetrace {

struct CacheGeometry {
  std::string name;
  std::size_t line_bytes = 64;
  std::size_t capacity_bytes = 0;
  std::size_t ways = 1;
  std::size_t sets() const { return capacity_bytes / (line_bytes * ways); }
  bool operator==(const CacheGeometry&) const = default;
};
// "paper_l2" (6 MiB, 24-way), "l1d" (32 KiB, 8-way), "l2" (512 KiB, 8-way); 64-byte lines.
// Throws std::invalid_argument naming the known presets.
CacheGeometry cache_preset(std::string_view name);
// Throws std::invalid_argument unless the line is a power of two and capacity is a whole,
// non-zero number of sets of `ways` lines.
void validate_cache_geometry(const CacheGeometry& geometry);

struct CacheCounters {
  std::uint64_t accesses = 0;  // cache lines read (a read spanning two lines counts two)
  std::uint64_t misses = 0;
};

class CacheSimulator {
 public:
  CacheSimulator(const CacheGeometry& geometry, std::size_t clients = 1);

  // Reads [address, address + bytes) for `client`; not thread-safe (one per thread).
  void access(const void* address, std::size_t bytes, std::size_t client) {
    const std::uintptr_t first = reinterpret_cast<std::uintptr_t>(address) >> line_shift_;
    const std::uintptr_t last = (reinterpret_cast<std::uintptr_t>(address) + bytes - 1) >> line_shift_;
    for (std::uintptr_t line = first; line <= last; ++line) access_line(line, client);
  }
  CacheCounters counters(std::size_t client) const { return counters_[client]; }
  const CacheGeometry& geometry() const { return geometry_; }

 private:
  void access_line(std::uintptr_t line, std::size_t client);

  CacheGeometry geometry_;
  unsigned line_shift_;
  std::size_t sets_;
  // Per set, `ways` tags (line numbers + 1; 0 is empty) and their last-use stamps.
  std::vector<std::uintptr_t> tags_;
  std::vector<std::uint64_t> last_use_;
  std::uint64_t clock_ = 0;
  std::vector<CacheCounters> counters_;
};

// One simulated cache per worker thread, like per-core caches.
class CacheBank {
 public:
  CacheBank(const CacheGeometry& geometry, std::size_t threads, std::size_t clients = 1);
  CacheSimulator& for_thread(std::size_t thread) { return *caches_[thread]; }
  std::size_t threads() const { return caches_.size(); }
  CacheCounters total(std::size_t client) const;
  const CacheGeometry& geometry() const { return caches_.front()->geometry(); }

 private:
  std::vector<std::unique_ptr<CacheSimulator>> caches_;
};

}  // namespace wavetrace
