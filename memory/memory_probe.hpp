// Probes: what traversal code reports about each memory read (address, bytes). Traversal
// is a template over the probe type; with NullProbe every report compiles to nothing, so
// the uninstrumented trace pays no cost. RecordingProbe feeds the pager and/or a cache.
#pragma once

#include <cstddef>
#include <cstdint>

#include "memory/cache_simulator.hpp"
#include "memory/pager.hpp"

namespace wavetrace {

struct NullProbe {
  static constexpr bool kRecords = false;
  void read(const void*, std::size_t) {}
};

// What a run observes: the shared page pool and one simulated cache per thread, each
// optional. `client` numbers the stage whose reads are counted apart.
struct MemoryObservers {
  Pager* pager = nullptr;
  CacheBank* caches = nullptr;
  bool any() const { return pager != nullptr || caches != nullptr; }
};

// One thread's probe for one batch: lives on the stack of the stage call.
class RecordingProbe {
 public:
  static constexpr bool kRecords = true;

  RecordingProbe(const MemoryObservers& observers, std::size_t client, std::size_t thread)
      : pager_(observers.pager),
        cache_(observers.caches ? &observers.caches->for_thread(thread % observers.caches->threads()) : nullptr),
        client_(client) {}
  RecordingProbe(const RecordingProbe&) = delete;
  RecordingProbe& operator=(const RecordingProbe&) = delete;
  ~RecordingProbe() {
    if (pager_ != nullptr && repeated_page_reads_ > 0) pager_->add_accesses(repeated_page_reads_, client_);
  }

  void read(const void* address, std::size_t bytes) {
    if (cache_ != nullptr) cache_->access(address, bytes, client_);
    if (pager_ == nullptr) return;
    const std::uint32_t first = pager_->page_of(address);
    const std::uint32_t last = pager_->page_of(static_cast<const std::byte*>(address) + bytes - 1);
    read_page(first);
    if (last != first) read_page(last);  // reads are far smaller than a page: two at most
  }

 private:
  // A read of the page this thread read last needs no LRU update: it is still the most
  // recent page (exactly so with one thread; with more, another thread may have moved it).
  void read_page(std::uint32_t page) {
    if (page == last_page_ && page != Pager::kNoPage) {
      ++repeated_page_reads_;
      return;
    }
    pager_->touch(page, client_);
    last_page_ = page;
  }

  Pager* pager_;
  CacheSimulator* cache_;
  std::size_t client_;
  std::uint32_t last_page_ = Pager::kNoPage;
  std::uint64_t repeated_page_reads_ = 0;
};

}  // namespace wavetrace
