// Real out-of-core paging of a file, the reordering paper's setting (§5) made real: the
// file's bytes appear at one fixed address range, but only `budget` bytes of them are ever
// resident, in a pool of page slots (a memfd), filled on demand by reads that bypass the OS
// page cache (O_DIRECT) and evicted least recently used. Pages come in two ways: a probe
// reports a read (touch, which also keeps the LRU order exact), or traversal reads a page
// no probe announced, which faults (SIGSEGV on the reserved range) and is loaded by the
// signal handler before the read is retried. Either way the bytes a reader sees are the
// file's; an eviction racing a reader only costs that reader another fault.
#pragma once

#include <cstddef>
#include <cstdint>
#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

namespace wavetrace {

struct DiskCounters {
  std::uint64_t faults = 0;      // pages read from the file
  std::uint64_t bytes_read = 0;
  double read_seconds = 0.0;     // measured around the reads
  // Time a reader waited for a page to become resident: its own read and mapping, or another
  // thread's read of the same page. Reads of different pages overlap, so this can exceed
  // read_seconds on one thread and fall short of it summed over threads.
  double wait_seconds = 0.0;
};

class FilePager {
 public:
  // `page_bytes`: a power of two, at least 4096; `budget_bytes` is rounded down to whole
  // pages, and less than one page is an error naming memory.budget. `clients` counters are kept apart (one per stage that reads), plus
  // one for reads outside any client scope (loading). Throws std::runtime_error naming the
  // file when it cannot be opened for direct reads or the address range reserved.
  FilePager(const std::string& path, std::uint64_t file_bytes, std::size_t page_bytes, std::size_t budget_bytes,
            std::size_t clients);
  ~FilePager();
  FilePager(const FilePager&) = delete;
  FilePager& operator=(const FilePager&) = delete;

  // Where the file's byte 0 appears.
  const std::byte* base() const { return base_; }
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

  DiskCounters counters(std::size_t client) const;
  DiskCounters total() const;
  // The most page reads under way at once since the last reset (one per thread reading).
  std::size_t reads_in_flight_max() const;
  std::size_t page_bytes() const { return page_bytes_; }
  std::size_t budget_bytes() const { return slots_ * page_bytes_; }
  std::size_t page_count() const { return slot_of_.size(); }

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
  std::string load(std::uint32_t page, std::unique_lock<std::mutex>& lock);
  void evict_locked(std::uint32_t page);
  void unlink_locked(std::uint32_t page);
  void push_front_locked(std::uint32_t page);
  std::size_t client_index() const;
  void release();  // unregisters, unmaps and closes: what the destructor does

  std::string path_;
  std::uint64_t file_bytes_;
  std::size_t page_bytes_;
  unsigned page_shift_;
  std::size_t reserved_bytes_;
  std::size_t slots_;
  int direct_fd_ = -1;  // the file, O_DIRECT
  int pool_fd_ = -1;    // the memfd of page slots
  std::byte* base_ = nullptr;
  // The whole pool mapped writable once: reads land in their slot directly (O_DIRECT into
  // the memfd's pages), then the slot is mapped read-only at the page's address.
  std::byte* pool_view_ = nullptr;

  mutable std::mutex mutex_;
  std::condition_variable loaded_;  // a page finished loading (or failed to)
  std::size_t reads_in_flight_ = 0, reads_in_flight_max_ = 0;
  std::vector<std::uint32_t> slot_of_;        // per page: its pool slot, kNone when not resident
  std::vector<std::uint32_t> previous_, next_; // the LRU list, most recent at head_
  std::uint32_t head_ = kNone, tail_ = kNone;
  std::vector<std::uint32_t> free_slots_;
  std::vector<DiskCounters> clients_;
};

}  // namespace wavetrace
