// Real out-of-core paging of a file, the reordering paper's setting (§5) made real: the
// file's bytes appear at one fixed address range, but only `budget` bytes of them are ever
// resident, filled on demand by reads that bypass the OS page cache (O_DIRECT) and evicted
// least recently used, a few at a time (one TLB flush for the group). Pages come in two
// ways: a probe reports a read (touch, which also keeps the LRU order), or traversal reads a
// page no probe announced, which faults (SIGBUS or SIGSEGV on the reserved range) and is
// loaded by the signal handler before the read is retried. Either way the bytes a reader
// sees are the file's; an eviction racing a reader only costs that reader another fault.
// With frames (use_frames), walks that ask for it read a page where it lies in a frame of
// fixed address instead, pinned while they read it: no page is mapped or unmapped a read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "wavetrace/memory/page_mapping.hpp"

namespace wavetrace {

class PageTrace;

struct DiskCounters {
  std::uint64_t faults = 0;      // pages read from the file
  // Of those, pages brought in by a fault in the read itself (a signal, in this pager): a read
  // no probe announced, or a page another thread evicted between announcement and read.
  std::uint64_t unannounced = 0;
  std::uint64_t bytes_read = 0;
  double read_seconds = 0.0;     // measured around the reads
  // Time a reader waited for a page to become resident: its own read and mapping, or another
  // thread's read of the same page. Reads of different pages overlap, so this can exceed
  // read_seconds on one thread and fall short of it summed over threads.
  double wait_seconds = 0.0;
};

// A byte range of the paged file that belongs to one named part of it (a world's chunk
// nodes, leaf records, vertices...), so that faults can be counted by part.
struct FilePart {
  std::uint64_t offset = 0, bytes = 0;
  std::uint32_t part = 0;  // index into the names given with the parts
};

// How many distinct pages runs of consecutive rays touched: the reordering's sharing seen
// from the pager. A window is a fixed number of rays in the order they were traced.
struct RayWindowCounters {
  std::uint64_t windows = 0;
  std::uint64_t distinct_pages = 0;  // summed over the windows
};

class FilePager {
 public:
  // `page_bytes`: a power of two, at least 4096; `budget_bytes` is rounded down to whole
  // pages, and less than one page (two, for a file of two or more) is an error naming
  // memory.budget. `clients` counters are kept apart (one per stage that reads), plus
  // one for reads outside any client scope (loading). Throws std::runtime_error naming the
  // file when it cannot be opened for direct reads or the address range reserved, and
  // naming memory.page_mapping when `mapping` asks for userfaultfd and the kernel refuses it.
  FilePager(const std::string& path, std::uint64_t file_bytes, std::size_t page_bytes, std::size_t budget_bytes,
            std::size_t clients, PageMapping mapping = PageMapping::automatic);
  ~FilePager();
  FilePager(const FilePager&) = delete;
  FilePager& operator=(const FilePager&) = delete;

  // Where the file's byte 0 appears.
  const std::byte* base() const { return base_; }
  // userfaultfd or memfd: the mapping in use, never automatic.
  PageMapping mapping() const { return fault_fd_ >= 0 ? PageMapping::userfaultfd : PageMapping::memfd; }
  std::uint64_t file_bytes() const { return file_bytes_; }
  bool contains(const void* address) const {
    const auto* p = static_cast<const std::byte*>(address);
    return p >= base_ && p < base_ + reserved_bytes_;
  }

  // Marks the page holding `address` most recently used, reading it first if it is not
  // resident. Thread-safe; addresses outside the file are ignored.
  void touch(const void* address);
  // Evicts every page and zeroes the counters, so a render starts from an empty pool.
  void reset();

  // Frames: most of the budget becomes frames, buffers at addresses that never change, each
  // holding one page and the file's next kFrameTailBytes after it, so that a record that
  // starts in the page and runs on into the next (up to that much) reads whole. A page comes
  // in by one direct read into a free frame and leaves by that frame's reuse: no page is
  // mapped, copied or unmapped, and no 4 KiB of a frame is ever new to the MMU (in this
  // virtual machine, a hypervisor exit of about 2 us each: 35 us of a 64 KiB page's read).
  // Walks that read through pin() use them; every other read goes through the file's range
  // as before, into the rest of the budget: a kMappedPoolShare-th of it, 2 to
  // kMappedPoolMaxPages pages (a chunked world's top tree, a leaf no frame was free for).
  // Switched only while the pool is empty and no reader runs (after reset); refused (false)
  // for pages under kMinFramePageBytes, whose tail would cost over an eighth of each frame,
  // and for budgets of fewer than kMinFrames frames.
  static constexpr std::size_t kFrameTailBytes = 4096;
  static constexpr std::size_t kMinFramePageBytes = 32 * 1024;
  static constexpr std::size_t kMinFrames = 8;
  static constexpr std::size_t kMappedPoolShare = 64, kMappedPoolMaxPages = 64;
  bool use_frames(bool wanted);
  bool framed() const { return frame_count_ > 0; }
  std::size_t frame_count() const { return frame_count_; }
  // Framed: makes the page holding `address` resident in a frame (reading it first if it is
  // not) and pins it there until unpin(frame); returns where that frame shows the page's
  // first byte, the page's bytes then the tail. Null where `address` is not the file's or
  // every frame is pinned or being read (the caller then reads through the file's range).
  // Thread-safe; throws std::runtime_error naming the file when the read fails.
  const std::byte* pin(const void* address, std::uint32_t& frame);
  void unpin(std::uint32_t frame) { pins_[frame].fetch_sub(1, std::memory_order_release); }
  // Every touch from now on is also recorded in `trace` (null: none). Set while no reader runs.
  void set_page_trace(PageTrace* trace) { page_trace_ = trace; }

  // Names the file's parts: each extent's faults count to names[extent.part]; bytes no
  // extent covers count to a last part, "other". Extents may come in any order but must
  // not overlap. Call before the first read.
  void name_parts(std::vector<std::string> names, std::vector<FilePart> extents);
  // The part names, "other" last, and the faults of `client` (every client's with
  // kAllClients) by part, in that order.
  static constexpr std::size_t kAllClients = ~std::size_t{0};
  const std::vector<std::string>& part_names() const { return part_names_; }
  std::vector<std::uint64_t> faults_by_part(std::size_t client) const;

  // Pages loaded by `client` count as prefetched: read ahead of the readers that need them
  // (a trace's look-ahead). A prefetched page another client reads before it is evicted is a
  // prefetch hit, whether the read finds it loaded or still loading.
  void set_prefetch_client(std::size_t client) { prefetch_client_ = client; }
  std::uint64_t prefetch_hits() const { return prefetch_hits_.load(std::memory_order_relaxed); }

  // Adds windows of consecutive rays, each with the distinct pages it touched.
  void add_ray_windows(const RayWindowCounters& windows);
  RayWindowCounters ray_windows() const;

  DiskCounters counters(std::size_t client) const;
  DiskCounters total() const;
  // The most page reads under way at once since the last reset (one per thread reading).
  std::size_t reads_in_flight_max() const;
  std::size_t page_bytes() const { return page_bytes_; }
  std::size_t budget_bytes() const { return budget_pages_ * page_bytes_; }
  std::size_t page_count() const { return page_count_; }

  // The client this thread's faults count to while the scope lives.
  class ClientScope {
   public:
    explicit ClientScope(std::size_t client);
    ~ClientScope();
    ClientScope(const ClientScope&) = delete;
    ClientScope& operator=(const ClientScope&) = delete;

   private:
    std::size_t previous_;
  };

  // Called by the SIGSEGV handler: loads the page of `address` if it is in this file's
  // range; false otherwise.
  bool handle_fault(const void* address) noexcept;

 private:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;
  static constexpr std::uint32_t kLoading = 0xFFFFFFFEu;  // slot_of_: a thread is reading the page
  // Makes `page` resident and most recently used; `lock` (of mutex_) is held on entry and on
  // return, and released while the page is read, so reads of different pages overlap. A
  // reader of a page being loaded waits for it. Returns an error message, empty on success,
  // so the signal path never throws.
  std::string load(std::uint32_t page, std::uint64_t offset, std::unique_lock<std::mutex>& lock, bool by_fault = false);
  // load's two steps outside the lock: the page's bytes into a read buffer, then at its address.
  // `bytes` (at most the page and a frame's tail) from the page's start; zero past the file's end.
  std::string read_page(std::uint32_t page, std::byte* into, std::size_t bytes, double& seconds) const;
  std::string place_page(std::uint32_t page, std::uint32_t slot, const std::byte* into);
  // Where `page` starts, in the file and from base_ (the file starts on a page boundary).
  std::uint64_t offset_of_page(std::uint32_t page) const { return std::uint64_t(page) << page_shift_; }
  // The file's bytes in `page`: page_bytes_ but for the last page.
  std::size_t file_bytes_in(std::uint32_t page) const {
    return static_cast<std::size_t>(std::min<std::uint64_t>(page_bytes_, file_bytes_ - offset_of_page(page)));
  }
  // The part of the file holding byte `offset`.
  std::uint32_t part_of(std::uint64_t offset) const;
  std::uint64_t offset_of(const void* address) const {
    return std::uint64_t(static_cast<const std::byte*>(address) - base_);
  }
  std::uint32_t page_of(const void* address) const {
    return static_cast<std::uint32_t>(offset_of(address) >> page_shift_);
  }
  // Evicts the `count` least recently used pages (at most kMaxEvictionGroup) in one go.
  void evict_tail_locked(std::size_t count);
  // Sizes the mapped pool to `slots` pages (empty, under the lock).
  void size_mapped_pool_locked(std::size_t slots);
  // `bytes` of fresh anonymous memory starting on an `alignment` boundary (a power of two),
  // mapped with `protection` and `flags` (MAP_PRIVATE | MAP_ANONYMOUS and more); null when
  // the kernel refuses, errno saying why.
  static std::byte* map_aligned(std::size_t bytes, std::size_t alignment, int protection, int flags);
  // Adds the time since `since` to the calling thread's client's waits.
  void count_wait_locked(std::chrono::steady_clock::time_point since);
  // Counts one page read for the calling thread's client.
  void count_read_locked(std::uint32_t page, std::uint64_t address_offset, double seconds, bool by_fault);
  // Framed: the frame holding `page`, read into one first if need be, moved to the head of
  // the frames' LRU order; kNone when no frame could be freed. `lock` as in load().
  std::uint32_t load_frame(std::uint32_t page, std::uint64_t address_offset, std::unique_lock<std::mutex>& lock);
  // Frees the least recently used frame no reader has pinned; false when every one is.
  bool evict_frame_locked();
  std::byte* frame_bytes(std::uint32_t frame) const { return frames_ + std::size_t(frame) * frame_stride_; }
  void release_frames();
  // A full pool evicts an eighth of itself, up to 8 pages, at a time: a shootdown per group,
  // not per fault. room:8M, hph_origin, 128 KiB pages (A/B, one run each): at 24% (140
  // slots) 14.7 s with 1, 12.1 with 4, 12.3 with 8, 13.3 with 16 (the pool partly idle); at
  // 10% (58 slots) 41.7 s with 1, 31.3 with 2, 25.3 with 4, 23.4 with 8; 2-8% more faults.
  static constexpr std::size_t kMaxEvictionGroup = 8;
  // A reader other than the prefetcher reached `page`: the first such read of a prefetched page is a hit.
  void count_prefetch_hit(std::uint32_t page) {
    if (prefetched_[page].load(std::memory_order_relaxed) != 0 && client_index() != prefetch_client_ &&
        prefetched_[page].exchange(0, std::memory_order_relaxed) != 0) {
      prefetch_hits_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  // An LRU order over the entries 0..n-1 (the mapped pool's pages, or the frames): a doubly
  // linked list, most recent at head, changed under mutex_; each entry stamped with the
  // order's clock (one tick a push) when it went to the head, read without the lock.
  struct LruOrder {
    std::vector<std::uint32_t> previous, next;
    std::uint32_t head = kNone, tail = kNone;
    std::atomic<std::uint64_t> clock{0};
    std::unique_ptr<std::atomic<std::uint64_t>[]> headed_at;
    void reset(std::size_t entries);  // empty, for `entries` entries
    bool empty() const { return tail == kNone; }
    void unlink(std::uint32_t entry);
    void push_front(std::uint32_t entry);
    void move_to_front(std::uint32_t entry) {
      if (head == entry) return;
      unlink(entry);
      push_front(entry);
    }
    // Went to the head fewer than `ticks` pushes ago.
    bool fresh(std::uint32_t entry, std::uint64_t ticks) const {
      return clock.load(std::memory_order_relaxed) - headed_at[entry].load(std::memory_order_relaxed) < ticks;
    }
  };
  std::size_t client_index() const;
  void release();  // unregisters, unmaps and closes: what the destructor does

  std::string path_;
  std::uint64_t file_bytes_;
  std::size_t page_bytes_;
  unsigned page_shift_;
  std::size_t reserved_bytes_;
  std::size_t budget_pages_;  // the budget in pages
  std::size_t slots_;         // the mapped pool's: the budget's pages, or with frames the mapped pool's share
  int direct_fd_ = -1;  // the file, O_DIRECT
  int fault_fd_ = -1;   // the userfaultfd the range is registered with (PageMapping::userfaultfd)
  int pool_fd_ = -1;    // the memfd of page slots (PageMapping::memfd)
  std::byte* base_ = nullptr;

  mutable std::mutex mutex_;
  std::condition_variable loaded_;  // a page finished loading (or failed to)
  std::size_t reads_in_flight_ = 0, reads_in_flight_max_ = 0;
  // Per page: its pool slot (with userfaultfd, only a count: the kernel holds the bytes),
  // kNone when not resident. Written under mutex_, read without it
  // by touch's fast path.
  std::unique_ptr<std::atomic<std::uint32_t>[]> slot_of_;
  std::size_t page_count_ = 0;
  // The mapped pool's LRU order, over pages. A resident page put at its head fewer than
  // `fresh_ticks_` (a quarter of the pool) pushes ago is still in its first quarter, far from
  // eviction, so a touch of it takes no lock and leaves it where it is: the order is LRU's
  // but for such touches, which may leave a page up to a quarter of the pool further back
  // than exact LRU would (2-3% more faults on room:8M, 3-5% less time). Frames do the same.
  LruOrder mapped_order_;
  std::uint64_t fresh_ticks_ = 1;
  std::vector<std::uint32_t> free_slots_;
  std::size_t eviction_group_ = 1;  // pages evicted at once when the pool is full
  int self_pidfd_ = -1;  // this process, for process_madvise; -1 once the kernel refused it
  std::vector<DiskCounters> clients_;
  std::size_t prefetch_client_ = ~std::size_t{0};
  // Per page: loaded by the prefetcher and not yet read by another client.
  std::unique_ptr<std::atomic<std::uint8_t>[]> prefetched_;
  std::atomic<std::uint64_t> prefetch_hits_{0};
  std::vector<std::string> part_names_ = {"other"};
  std::vector<FilePart> parts_;                  // sorted by offset
  std::vector<std::uint64_t> part_faults_;       // clients_.size() rows of part_names_.size()
  RayWindowCounters ray_windows_;
  PageTrace* page_trace_ = nullptr;

  // Frames (use_frames): frame_count_ buffers of frame_stride_ bytes from frames_.
  std::byte* frames_ = nullptr;
  std::size_t frames_bytes_ = 0, frame_stride_ = 0, frame_count_ = 0;
  // Per page: its frame, kNone, or kLoading while a thread reads it into one. Read without
  // the lock by pin's fast path, which pins the frame and then checks the page is still
  // there; eviction marks the page gone and then checks the frame is unpinned (both seq_cst:
  // one of the two sees the other).
  std::unique_ptr<std::atomic<std::uint32_t>[]> frame_of_;
  std::unique_ptr<std::atomic<std::uint32_t>[]> pins_;          // per frame: readers holding it
  std::vector<std::uint32_t> page_in_frame_;  // per frame
  LruOrder frame_order_;                      // over frames
  std::vector<std::uint32_t> free_frames_;
  std::uint64_t frame_fresh_ticks_ = 1;
};

}  // namespace wavetrace
