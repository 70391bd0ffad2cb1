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
  template <typename T>
  const T* resident(const T* address, std::size_t) { return address; }
  template <std::size_t kMaxBytes>
  const std::byte* resident_record(const std::byte* address) { return address; }
  void record_read(const void*, std::size_t) {}
  void end_ray() {}
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
      framed_ = file_pager_->framed();
    }
  }
  RecordingProbe(const RecordingProbe&) = delete;
  RecordingProbe& operator=(const RecordingProbe&) = delete;
  ~RecordingProbe() {
    end_ray();
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
    if (file_pager_ != nullptr) {
      // The page is loaded now, before the read it announces; a page change is a touch.
      const auto first = reinterpret_cast<std::uintptr_t>(address) >> file_page_shift_;
      const auto last = (reinterpret_cast<std::uintptr_t>(address) + bytes - 1) >> file_page_shift_;
      if (first != last_file_page_) touch_file_page(address, first);
      if (last != first) touch_file_page(static_cast<const std::byte*>(address) + bytes - 1, last);
      last_file_page_ = last;
    }
    observe_read(address, bytes);
  }

  // Walks that read through these may be given the bytes in a pager's frame (file_pager.hpp,
  // "Frames") instead of at `address`: they read there, and keep what they got until
  // end_ray(), which lets the frames go. Unframed, these are read() and announce().
  // A read of `bytes` (at most FilePager::kFrameTailBytes) at `address`: where to read them.
  template <typename T>
  const T* resident(const T* address, std::size_t bytes) {
    if (!framed_ || bytes > FilePager::kFrameTailBytes) {
      read(address, bytes);
      return address;
    }
    if (tally_ != nullptr) tally_->count(thread_, address);
    observe_read(address, bytes);
    return reinterpret_cast<const T*>(in_frame(reinterpret_cast<const std::byte*>(address)));
  }
  // A read that starts at `address` and whose size only the read tells, at most kMaxBytes:
  // where to read it. record_read() follows, with the size.
  template <std::size_t kMaxBytes>
  const std::byte* resident_record(const std::byte* address) {
    static_assert(kMaxBytes <= FilePager::kFrameTailBytes, "a frame's tail holds the part of a record past its page");
    if (!framed_) {
      announce(address);
      return address;
    }
    return in_frame(address);
  }
  void record_read(const void* address, std::size_t bytes) {
    if (!framed_) return read(address, bytes);
    if (tally_ != nullptr) tally_->count(thread_, address);
    observe_read(address, bytes);
  }
  // The walk of one ray is done: the frames it read are let go.
  void end_ray() {
    for (std::size_t k = 0; k < pinned_count_; ++k) {
      if (pinned_[k].frame != kNoFrame) file_pager_->unpin(pinned_[k].frame);
    }
    pinned_count_ = 0;
    current_pinned_ = kNoFilePage;
  }

 private:
  // The reads the cache and the simulated pager count (not the real pager's).
  void observe_read(const void* address, std::size_t bytes) {
    if (cache_ != nullptr) cache_->access(address, bytes, client_);
    if (pager_ == nullptr) return;
    const std::uint32_t first = pager_->page_of(address);
    const std::uint32_t last = pager_->page_of(static_cast<const std::byte*>(address) + bytes - 1);
    read_page(first);
    if (last != first) read_page(last);  // reads are far smaller than a page: two at most
  }

  // Where `address` reads in a frame, the frame pinned for this ray: the page read last
  // without a look, one this ray pinned before by a short search, else a pin. Where the
  // address is not the file's, or no frame is free (or this ray holds kMaxPinned already),
  // it reads where it is (through the file's range: the pager's mapped pool).
  const std::byte* in_frame(const std::byte* address) {
    const auto page = reinterpret_cast<std::uintptr_t>(address) >> file_page_shift_;
    if (page == current_pinned_) return address + current_offset_;
    if (counting_windows_) note_window_page(page);
    for (std::size_t k = 0; k < pinned_count_; ++k) {
      if (pinned_[k].page == page) {
        current_pinned_ = page;
        current_offset_ = pinned_[k].offset;
        return address + current_offset_;
      }
    }
    Pinned pinned{page, kNoFrame, 0};
    const std::byte* frame = pinned_count_ < kMaxPinned ? file_pager_->pin(address, pinned.frame) : nullptr;
    if (frame != nullptr) {
      pinned.offset = frame - reinterpret_cast<const std::byte*>(page << file_page_shift_);
    } else {
      file_pager_->touch(address);  // ignored where the address is not the file's
    }
    if (pinned_count_ < kMaxPinned) pinned_[pinned_count_++] = pinned;
    current_pinned_ = page;
    current_offset_ = pinned.offset;
    return address + current_offset_;
  }

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

  // Frames this ray reads (in_frame): each page's offset from the file's address to the
  // frame's (0 where it reads in place) and its frame (kNoFrame then).
  static constexpr std::size_t kMaxPinned = 32;
  static constexpr std::uint32_t kNoFrame = ~std::uint32_t{0};
  struct Pinned {
    std::uintptr_t page;
    std::uint32_t frame;
    std::ptrdiff_t offset;
  };
  bool framed_ = false;
  std::array<Pinned, kMaxPinned> pinned_;
  std::size_t pinned_count_ = 0;
  std::uintptr_t current_pinned_ = kNoFilePage;
  std::ptrdiff_t current_offset_ = 0;
};

}  // namespace wavetrace
