// Probes: what traversal code reports about each memory read (address, bytes). Traversal
// is a template over the probe type; with NullProbe every report compiles to nothing, so
// the uninstrumented trace pays no cost. RecordingProbe feeds the pager and/or a cache.
#pragma once

#include <cstddef>
#include <cstdint>

#include <algorithm>
#include <array>
#include <bit>
#include <optional>
#include <vector>

#include "wavetrace/memory/cache_simulator.hpp"
#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/memory/read_tally.hpp"
#include "wavetrace/memory/simulated_pager.hpp"

namespace wavetrace {

struct NullProbe {
  static constexpr bool kRecords = false;
  static constexpr bool counts_reads() { return false; }
  void read(const void*, std::size_t) {}
  void announce(const void*) {}
};

// What a run observes: the shared page pool and one simulated cache per thread, each
// optional. `client` numbers the stage whose reads are counted apart.
struct MemoryObservers {
  SimulatedPager* pager = nullptr;
  CacheBank* caches = nullptr;
  FilePager* file_pager = nullptr;  // real paging: reads keep its LRU order and load its pages
  ReadTally* tally = nullptr;       // reads counted by world array
  bool any() const { return pager != nullptr || caches != nullptr || file_pager != nullptr || tally != nullptr; }
};

// One thread's probe for one batch: lives on the stack of the stage call.
class RecordingProbe {
 public:
  static constexpr bool kRecords = true;

  RecordingProbe(const MemoryObservers& observers, std::size_t client, std::size_t thread)
      : pager_(observers.pager),
        cache_(observers.caches ? &observers.caches->for_thread(thread % observers.caches->threads()) : nullptr),
        file_pager_(observers.file_pager),
        tally_(observers.tally),
        client_(client),
        thread_(thread) {
    if (file_pager_ != nullptr) {
      file_page_shift_ = static_cast<unsigned>(std::countr_zero(file_pager_->page_bytes()));
      client_scope_.emplace(client);  // faults this thread takes count to this stage
    }
  }
  RecordingProbe(const RecordingProbe&) = delete;
  RecordingProbe& operator=(const RecordingProbe&) = delete;
  ~RecordingProbe() {
    if (pager_ != nullptr && repeated_page_reads_ > 0) pager_->add_accesses(repeated_page_reads_, client_);
    if (file_pager_ != nullptr && windows_.windows > 0) file_pager_->add_ray_windows(windows_);
  }

  // Whether reads are counted (the simulated pager, caches, the tally), so that a walk must
  // read what the paper's model reads; real paging alone sees only the file's pages.
  bool counts_reads() const { return pager_ != nullptr || cache_ != nullptr || tally_ != nullptr; }

  // Real paging only: from now on the probe keeps the pages each window of rays touched.
  void count_ray_windows() { counting_windows_ = file_pager_ != nullptr; }
  // Closes a window of consecutive rays (real paging only): a full one (`counted`) adds the
  // distinct file pages its reads touched to the windows' counters; a short one, the tail
  // of a run of one ray kind, is dropped, so every counted window has the same ray count.
  void end_ray_window(bool counted) {
    if (!counting_windows_) return;
    if (counted) {
      std::sort(window_pages_.begin(), window_pages_.end());
      windows_.distinct_pages +=
          std::size_t(std::unique(window_pages_.begin(), window_pages_.end()) - window_pages_.begin());
      ++windows_.windows;
    }
    window_pages_.clear();
    recent_window_pages_ = filled_with_no_page();
    last_file_page_ = kNoFilePage;  // the next window's first page counts to it
  }

  // A read about to start whose size only the read itself tells (a leaf record, sized by its
  // decode): its first page is loaded now, for the real pager alone; the read() that follows
  // with the size counts it for every observer and announces the page it ends on, if another.
  void announce(const void* address) {
    if (file_pager_ == nullptr) return;
    const auto page = reinterpret_cast<std::uintptr_t>(address) >> file_page_shift_;
    if (page != last_file_page_) touch_file_page(address, page);
    last_file_page_ = page;
  }

  void read(const void* address, std::size_t bytes) {
    if (tally_ != nullptr) tally_->count(thread_, address);
    if (cache_ != nullptr) cache_->access(address, bytes, client_);
    if (file_pager_ != nullptr) {
      // The page is loaded now, before the read it announces; a page change is a touch.
      const auto first = reinterpret_cast<std::uintptr_t>(address) >> file_page_shift_;
      const auto last = (reinterpret_cast<std::uintptr_t>(address) + bytes - 1) >> file_page_shift_;
      if (first != last_file_page_) touch_file_page(address, first);
      if (last != first) touch_file_page(static_cast<const std::byte*>(address) + bytes - 1, last);
      last_file_page_ = last;
    }
    if (pager_ == nullptr) return;
    const std::uint32_t first = pager_->page_of(address);
    const std::uint32_t last = pager_->page_of(static_cast<const std::byte*>(address) + bytes - 1);
    read_page(first);
    if (last != first) read_page(last);  // reads are far smaller than a page: two at most
  }

 private:
  // The real pager loads `page` (holding `address`) or marks it recently used.
  void touch_file_page(const void* address, std::uintptr_t page) {
    file_pager_->touch(address);
    if (counting_windows_) note_window_page(page);
  }

  // A walk turns among a few pages (its nodes', its leaves', its vertices'): a page among the
  // last few noted is not kept again, so the window's sort sees tens of pages, not thousands.
  void note_window_page(std::uintptr_t page) {
    std::uintptr_t& recent = recent_window_pages_[page % recent_window_pages_.size()];
    if (recent == page) return;
    recent = page;
    window_pages_.push_back(page);
  }

  // A read of the page this thread read last needs no LRU update: it is still the most
  // recent page (exactly so with one thread; with more, another thread may have moved it).
  void read_page(std::uint32_t page) {
    if (page == last_page_ && page != SimulatedPager::kNoPage) {
      ++repeated_page_reads_;
      return;
    }
    pager_->touch(page, client_);
    last_page_ = page;
  }

  static constexpr std::uintptr_t kNoFilePage = ~std::uintptr_t{0};  // no address's page number
  static std::array<std::uintptr_t, 16> filled_with_no_page() {
    std::array<std::uintptr_t, 16> pages;
    pages.fill(kNoFilePage);
    return pages;
  }

  SimulatedPager* pager_;
  CacheSimulator* cache_;
  FilePager* file_pager_;
  ReadTally* tally_;
  std::size_t client_;
  std::size_t thread_;
  unsigned file_page_shift_ = 0;
  std::uintptr_t last_file_page_ = kNoFilePage;
  std::optional<FilePager::ClientScope> client_scope_;
  std::vector<std::uintptr_t> window_pages_;  // file pages touched in this window, with repeats
  std::array<std::uintptr_t, 16> recent_window_pages_ = filled_with_no_page();
  RayWindowCounters windows_;
  bool counting_windows_ = false;
  std::uint32_t last_page_ = SimulatedPager::kNoPage;
  std::uint64_t repeated_page_reads_ = 0;
};

}  // namespace wavetrace
