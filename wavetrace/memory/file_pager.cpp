// The real pager: the file's range reserved once, pages copied into it on demand (by
// userfaultfd, or as memfd slots mapped over it), a SIGBUS and SIGSEGV handler for reads no
// probe announced. Reads happen outside the pool's lock: threads reading different pages keep
// that many reads in flight. Its frames are in page_frames.cpp.
#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/memory/page_trace.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>

#include <fcntl.h>
#include <linux/userfaultfd.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <sys/uio.h>
#include <unistd.h>

#include <fmt/format.h>

namespace wavetrace {
namespace {

// The pagers whose ranges the SIGSEGV handler serves; a fault elsewhere goes to the handler
// installed before ours (or the default: a crash, as without us).
constexpr std::size_t kMaxPagers = 16;
std::array<std::atomic<FilePager*>, kMaxPagers> active_pagers{};
std::once_flag handlers_installed;
// What was installed before ours: [0] for SIGSEGV (the memfd mapping's faults), [1] for
// SIGBUS (userfaultfd's).
std::array<struct sigaction, 2> previous_actions{};

void chain_to_previous(int signal, siginfo_t* info, void* context) {
  const struct sigaction& previous = previous_actions[signal == SIGBUS ? 1 : 0];
  if (previous.sa_flags & SA_SIGINFO) {
    if (previous.sa_sigaction != nullptr) return previous.sa_sigaction(signal, info, context);
  } else if (previous.sa_handler != SIG_IGN && previous.sa_handler != SIG_DFL && previous.sa_handler != nullptr) {
    return previous.sa_handler(signal);
  }
  // Default action: restore it and return, so the faulting read repeats and crashes as usual.
  ::signal(signal, SIG_DFL);
}

void on_fault(int signal, siginfo_t* info, void* context) {
  for (auto& slot : active_pagers) {
    FilePager* pager = slot.load(std::memory_order_acquire);
    if (pager != nullptr && pager->handle_fault(info->si_addr)) return;
  }
  chain_to_previous(signal, info, context);
}

void install_handlers() {
  std::call_once(handlers_installed, [] {
    struct sigaction action {};
    action.sa_sigaction = on_fault;
    action.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&action.sa_mask);
    for (const int signal : {SIGSEGV, SIGBUS}) {
      if (sigaction(signal, &action, &previous_actions[signal == SIGBUS ? 1 : 0]) != 0) {
        throw std::runtime_error(fmt::format("cannot install the pager's {} handler: {}",
                                             signal == SIGBUS ? "SIGBUS" : "SIGSEGV", std::strerror(errno)));
      }
    }
  });
}

constexpr std::size_t kNoClient = ~std::size_t{0};
thread_local std::size_t current_client = kNoClient;

// A thread's buffer for direct reads, grown to the largest page it has read; from mmap, not
// malloc, since a read may be made from the SIGSEGV handler. Held until the thread exits.
struct ReadBuffer {
  std::byte* bytes = nullptr;
  std::size_t size = 0;
  ~ReadBuffer() {
    if (bytes != nullptr) ::munmap(bytes, size);
  }
  std::byte* at_least(std::size_t wanted) {
    if (size >= wanted) return bytes;
    void* grown = ::mmap(nullptr, wanted, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (grown == MAP_FAILED) return nullptr;
    if (bytes != nullptr) ::munmap(bytes, size);
    bytes = static_cast<std::byte*>(grown);
    size = wanted;
    return bytes;
  }
};
thread_local ReadBuffer read_buffer;

// Replaces a range with fresh PROT_NONE address space (no memory behind it).
bool reserve_range(void* address, std::size_t bytes) {
  return ::mmap(address, bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE | MAP_FIXED, -1, 0) != MAP_FAILED;
}

// Makes the PROT_NONE reservation [address, +bytes) readable anonymous memory whose missing
// pages raise SIGBUS in the thread that reads them, and returns the userfaultfd that fills
// them; on failure puts the reservation back and returns -1 with the kernel's reason. Huge
// pages stay off the range: a page is the pager's page and no larger.
int register_missing_pages(std::byte* address, std::size_t bytes, std::string& reason) {
  const int fd = static_cast<int>(::syscall(SYS_userfaultfd, O_CLOEXEC | O_NONBLOCK));
  if (fd < 0) {
    reason = fmt::format("userfaultfd: {}", std::strerror(errno));
    return -1;
  }
  uffdio_api api{};
  api.api = UFFD_API;
  api.features = UFFD_FEATURE_SIGBUS;
  uffdio_register range{};
  range.range = {reinterpret_cast<std::uint64_t>(address), bytes};
  range.mode = UFFDIO_REGISTER_MODE_MISSING;
  const char* step = nullptr;
  if (::ioctl(fd, UFFDIO_API, &api) != 0) {
    step = "UFFDIO_API with UFFD_FEATURE_SIGBUS";
  } else if (::mprotect(address, bytes, PROT_READ) != 0 || ::madvise(address, bytes, MADV_NOHUGEPAGE) != 0) {
    step = "making the range readable";
  } else if (::ioctl(fd, UFFDIO_REGISTER, &range) != 0) {
    step = "UFFDIO_REGISTER";
  } else if ((range.ioctls & (std::uint64_t{1} << _UFFDIO_COPY)) == 0) {
    step = "UFFDIO_COPY";
    errno = ENOTSUP;
  }
  if (step == nullptr) return fd;
  reason = fmt::format("{}: {}", step, std::strerror(errno));
  ::close(fd);
  reserve_range(address, bytes);
  return -1;
}

}  // namespace

FilePager::ClientScope::ClientScope(std::size_t client) : previous_(current_client) { current_client = client; }
FilePager::ClientScope::~ClientScope() { current_client = previous_; }

FilePager::FilePager(const std::string& path, std::uint64_t file_bytes, std::size_t page_bytes, std::size_t budget_bytes,
                     std::size_t clients, PageMapping mapping)
    : path_(path), file_bytes_(file_bytes), page_bytes_(page_bytes) {
  if (!std::has_single_bit(page_bytes) || page_bytes < 4096) {
    throw std::invalid_argument(fmt::format("page size {} bytes: real paging needs a power of two of 4096 or more", page_bytes));
  }
  if (budget_bytes < page_bytes) {
    throw std::invalid_argument(fmt::format("{}: memory.budget ({} bytes) is under one page (memory.page_bytes = {}): "
                                            "nothing could stay resident",
                                            path, budget_bytes, page_bytes));
  }
  page_shift_ = static_cast<unsigned>(std::countr_zero(page_bytes));
  const std::size_t pages = (file_bytes + page_bytes - 1) / page_bytes;
  if (pages >= kNone) throw std::invalid_argument(fmt::format("{}: {} pages of {} bytes is too many", path, pages, page_bytes));
  // One read may cross a page boundary (a record, or one unaligned load, across two pages):
  // in a pool of one page each half would evict the other, for ever.
  if (pages >= 2 && budget_bytes < 2 * page_bytes) {
    throw std::invalid_argument(fmt::format("{}: memory.budget ({} bytes) holds fewer than two pages (memory.page_bytes "
                                            "= {}): a read across a page boundary needs both pages resident at once",
                                            path, budget_bytes, page_bytes));
  }
  reserved_bytes_ = pages * page_bytes;
  budget_pages_ = std::clamp<std::size_t>(budget_bytes / page_bytes, 1, std::max<std::size_t>(pages, 1));
  slots_ = budget_pages_;
  direct_fd_ = ::open(path.c_str(), O_RDONLY | O_DIRECT | O_CLOEXEC);
  if (direct_fd_ < 0) throw std::runtime_error(fmt::format("{}: cannot open for direct reads: {}", path, std::strerror(errno)));
  // The range starts on a page boundary, so that a page of the file is a page_bytes-aligned
  // block of addresses: probes find a read's page from its address alone (address >>
  // log2(page_bytes)), and a probe that numbered pages off the pager's would let reads across
  // the pager's boundaries go unannounced (18% of room:64M's reads came in by fault so).
  base_ = map_aligned(reserved_bytes_, page_bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE);
  if (base_ == nullptr) {
    ::close(direct_fd_);
    throw std::runtime_error(fmt::format("{}: cannot reserve {} bytes of address space", path, reserved_bytes_));
  }
  if (mapping != PageMapping::memfd) {
    std::string reason;
    fault_fd_ = register_missing_pages(base_, reserved_bytes_, reason);
    if (fault_fd_ < 0 && mapping == PageMapping::userfaultfd) {
      release();
      throw std::runtime_error(fmt::format("{}: memory.page_mapping = userfaultfd, but the kernel refused it ({}); "
                                           "use auto or memfd", path, reason));
    }
  }
  if (fault_fd_ < 0) {
    // Each resident page is a mapping of its own, and a hole between two is another: the
    // kernel's limit on mappings bounds the pool.
    constexpr std::size_t kMaxSlots = 30000;
    if (slots_ > kMaxSlots) {
      release();
      throw std::invalid_argument(fmt::format(
          "{}: a budget of {} pages of {} KiB is over the {} pages real paging can map without userfaultfd; use larger "
          "pages (memory.page_bytes)", path, slots_, page_bytes >> 10, kMaxSlots));
    }
    pool_fd_ = ::memfd_create("wavetrace-page-pool", MFD_CLOEXEC);
    if (pool_fd_ < 0 || ::ftruncate(pool_fd_, off_t(slots_ * page_bytes)) != 0) {
      const std::string reason = std::strerror(errno);
      release();
      throw std::runtime_error(fmt::format("{}: cannot create a page pool of {} bytes: {}", path, slots_ * page_bytes, reason));
    }
  }
  page_count_ = pages;
  slot_of_ = std::make_unique<std::atomic<std::uint32_t>[]>(pages);
  prefetched_ = std::make_unique<std::atomic<std::uint8_t>[]>(pages);
  for (std::size_t p = 0; p < pages; ++p) slot_of_[p].store(kNone, std::memory_order_relaxed);
  self_pidfd_ = static_cast<int>(::syscall(SYS_pidfd_open, ::getpid(), 0));
  mapped_order_.reset(pages);
  size_mapped_pool_locked(budget_pages_);
  clients_.resize(clients + 1);
  part_faults_.assign(clients_.size() * part_names_.size(), 0);

  install_handlers();
  for (auto& slot : active_pagers) {
    FilePager* expected = nullptr;
    if (slot.compare_exchange_strong(expected, this)) return;
  }
  release();
  throw std::runtime_error(fmt::format("{}: more than {} paged files open at once", path, kMaxPagers));
}

FilePager::~FilePager() { release(); }

std::byte* FilePager::map_aligned(std::size_t bytes, std::size_t alignment, int protection, int flags) {
  void* region = ::mmap(nullptr, bytes + alignment, protection, flags, -1, 0);
  if (region == MAP_FAILED) return nullptr;
  // The part before the boundary and the part past `bytes` go back.
  const auto start = reinterpret_cast<std::uintptr_t>(region);
  const std::uintptr_t aligned = (start + alignment - 1) & ~std::uintptr_t(alignment - 1);
  if (aligned > start) ::munmap(region, aligned - start);
  if (const std::size_t tail = alignment - (aligned - start); tail > 0) {
    ::munmap(reinterpret_cast<std::byte*>(aligned) + bytes, tail);
  }
  return reinterpret_cast<std::byte*>(aligned);
}

void FilePager::size_mapped_pool_locked(std::size_t slots) {
  slots_ = slots;
  fresh_ticks_ = std::max<std::uint64_t>(slots_ / 4, 1);
  eviction_group_ = std::clamp<std::size_t>(slots_ / 8, 1, kMaxEvictionGroup);
  free_slots_.clear();
  for (std::size_t s = slots_; s-- > 0;) free_slots_.push_back(static_cast<std::uint32_t>(s));
}

void FilePager::release() {
  release_frames();
  for (auto& slot : active_pagers) {
    FilePager* expected = this;
    slot.compare_exchange_strong(expected, nullptr);
  }
  if (base_ != nullptr) ::munmap(base_, reserved_bytes_);
  base_ = nullptr;
  for (int* fd : {&direct_fd_, &fault_fd_, &pool_fd_, &self_pidfd_}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
}

std::size_t FilePager::client_index() const {
  return current_client < clients_.size() - 1 ? current_client : clients_.size() - 1;
}

void FilePager::LruOrder::reset(std::size_t entries) {
  previous.assign(entries, kNone);
  next.assign(entries, kNone);
  head = tail = kNone;
  headed_at = std::make_unique<std::atomic<std::uint64_t>[]>(entries);
}

void FilePager::LruOrder::unlink(std::uint32_t entry) {
  const std::uint32_t before = previous[entry], after = next[entry];
  (before == kNone ? head : next[before]) = after;
  (after == kNone ? tail : previous[after]) = before;
  previous[entry] = next[entry] = kNone;
}

void FilePager::LruOrder::push_front(std::uint32_t entry) {
  headed_at[entry].store(clock.fetch_add(1, std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  previous[entry] = kNone;
  next[entry] = head;
  if (head != kNone) previous[head] = entry;
  head = entry;
  if (tail == kNone) tail = entry;
}

void FilePager::evict_tail_locked(std::size_t count) {
  std::array<std::uint32_t, kMaxEvictionGroup> victims;
  std::size_t taken = 0;
  for (; taken < std::min(count, kMaxEvictionGroup) && !mapped_order_.empty(); ++taken) {
    victims[taken] = mapped_order_.tail;
    mapped_order_.unlink(mapped_order_.tail);
  }
  if (taken == 0) return;
  // Unmapping a page that a thread may have in its TLB costs a shootdown (an interrupt to
  // every other core running this process, and here, in a virtual machine, a slow one: 27%
  // of all cycles on room:8M at 24%, one per fault). One process_madvise(MADV_DONTNEED)
  // over the whole group clears them with one flush (measured on Linux 6.18: the shootdowns
  // fell under 2% of cycles); the PROT_NONE mappings that follow find no page left to flush.
  // Where the kernel refuses (older ones took few advices through process_madvise), each
  // page is unmapped (memfd) or dropped (userfaultfd) on its own, a flush each.
  bool dropped = false;
  if (taken > 1 && self_pidfd_ >= 0) {
    std::array<iovec, kMaxEvictionGroup> ranges;
    for (std::size_t v = 0; v < taken; ++v) ranges[v] = {base_ + offset_of_page(victims[v]), page_bytes_};
    const long advised = ::syscall(SYS_process_madvise, self_pidfd_, ranges.data(), taken, MADV_DONTNEED, 0);
    dropped = advised == long(taken * page_bytes_);
    if (advised < 0) {
      ::close(self_pidfd_);
      self_pidfd_ = -1;
    }
  }
  for (std::size_t v = 0; v < taken; ++v) {
    const std::uint32_t page = victims[v];
    // From here a reader of this page faults and waits for the mutex; its slot is free again.
    std::byte* place = base_ + offset_of_page(page);
    if (fault_fd_ < 0) {
      reserve_range(place, page_bytes_);
    } else if (!dropped) {
      // Its memory freed, the page is missing again. Should the kernel refuse, the page stays
      // resident past the budget, its bytes still the file's (this range is no slot's).
      ::madvise(place, page_bytes_, MADV_DONTNEED);
    }
    free_slots_.push_back(slot_of_[page].load(std::memory_order_relaxed));
    slot_of_[page].store(kNone, std::memory_order_relaxed);
    prefetched_[page].store(0, std::memory_order_relaxed);  // read by nobody else: a prefetch wasted
  }
}

// Reads `bytes` of the file from page `page`'s start into `into` (zero past the file's end),
// timing the read. The caller holds no lock.
std::string FilePager::read_page(std::uint32_t page, std::byte* into, std::size_t bytes, double& seconds) const {
  const std::uint64_t offset = offset_of_page(page);
  const std::size_t available = static_cast<std::size_t>(std::min<std::uint64_t>(bytes, file_bytes_ - offset));
  // O_DIRECT wants whole blocks: read whole 4 KiB (a section file's size is a multiple of
  // 4096, so the read ends at or before the file's end on a block boundary).
  const std::size_t request = (available + 4095) / 4096 * 4096;
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t done = 0; done < available && error.empty();) {
    const ssize_t got = ::pread(direct_fd_, into + done, request - done, off_t(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) {
      error = fmt::format("{}: reading page {} (bytes {}..{}) failed: {}", path_, page, offset, offset + available,
                          got < 0 ? std::strerror(errno)
                                  : "the file ends early (truncated or replaced while it was paged?)");
    }
    done += got > 0 ? std::size_t(got) : 0;
  }
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (error.empty() && available < bytes) std::memset(into + available, 0, bytes - available);
  return error;
}

// Makes the page read into `into` appear at its address, by the mapping in use. The caller
// holds no lock: the page is marked loading, so no other thread places or evicts it.
std::string FilePager::place_page(std::uint32_t page, std::uint32_t slot, const std::byte* into) {
  const std::uint64_t offset = offset_of_page(page);
  if (fault_fd_ >= 0) {
    // Copied in 4 KiB at a time, each mapped once whole: a reader sees the file's bytes or
    // faults on a part not yet in, and waits for this read.
    uffdio_copy copy{};
    copy.dst = reinterpret_cast<std::uint64_t>(base_ + offset);
    copy.src = reinterpret_cast<std::uint64_t>(into);
    copy.len = page_bytes_;
    while (::ioctl(fault_fd_, UFFDIO_COPY, &copy) != 0) {
      if (errno == EAGAIN && copy.copy >= 0) {  // interrupted part way: go on from there
        copy.dst += std::uint64_t(copy.copy), copy.src += std::uint64_t(copy.copy), copy.len -= std::uint64_t(copy.copy);
        copy.copy = 0;
        continue;
      }
      return fmt::format("{}: placing page {} failed: {}", path_, page, std::strerror(errno));
    }
    return {};
  }
  // Into the slot by a write to the memfd, not through a writable mapping of the pool: a
  // page mapped there and at its address counted twice in the process's resident memory
  // (VmRSS, VmHWM, what the OOM killer weighs: a 12 GB pool showed 24 GB), and unmapping
  // the view's pages a group at a time cost 27% of a paged render's time; this copy, no
  // time we could measure (docs/memory.md).
  for (std::size_t done = 0; done < page_bytes_;) {
    const ssize_t put = ::pwrite(pool_fd_, into + done, page_bytes_ - done, off_t(std::size_t(slot) * page_bytes_ + done));
    if (put < 0 && errno == EINTR) continue;
    if (put <= 0) return fmt::format("{}: copying page {} into the pool failed: {}", path_, page, std::strerror(errno));
    done += std::size_t(put);
  }
  // The page appears at its address read-only in one mmap, once it is whole: no reader
  // ever sees it half read. MAP_POPULATE maps every 4 KiB of it now: one call instead of a
  // minor fault each.
  if (::mmap(base_ + offset, page_bytes_, PROT_READ, MAP_SHARED | MAP_FIXED | MAP_POPULATE, pool_fd_,
             off_t(std::size_t(slot) * page_bytes_)) == MAP_FAILED) {
    return fmt::format("{}: mapping page {} failed: {}", path_, page, std::strerror(errno));
  }
  return {};
}

std::string FilePager::load(std::uint32_t page, std::uint64_t address_offset, std::unique_lock<std::mutex>& lock,
                            bool by_fault) {
  std::optional<std::chrono::steady_clock::time_point> waiting_since;
  for (;;) {
    const std::uint32_t state = slot_of_[page].load(std::memory_order_relaxed);
    if (state != kNone) count_prefetch_hit(page);
    if (state != kNone && state != kLoading) {
      mapped_order_.move_to_front(page);
      if (waiting_since) count_wait_locked(*waiting_since);
      return {};
    }
    if (!waiting_since) waiting_since = std::chrono::steady_clock::now();
    // Another thread reads this page, or every slot is taken by reads under way: wait.
    if (state == kLoading || (free_slots_.empty() && mapped_order_.empty())) {
      loaded_.wait(lock);
      continue;
    }
    break;
  }
  if (free_slots_.empty()) evict_tail_locked(eviction_group_);
  const std::uint32_t slot = free_slots_.back();
  free_slots_.pop_back();
  slot_of_[page].store(kLoading, std::memory_order_relaxed);
  reads_in_flight_max_ = std::max(reads_in_flight_max_, ++reads_in_flight_);
  lock.unlock();

  const std::uint64_t offset = offset_of_page(page);
  std::byte* into = read_buffer.at_least(page_bytes_);
  double seconds = 0.0;
  std::string error = into == nullptr
                          ? fmt::format("{}: no memory for a read buffer of {} bytes", path_, page_bytes_)
                          : read_page(page, into, page_bytes_, seconds);
  if (error.empty()) error = place_page(page, slot, into);

  lock.lock();
  --reads_in_flight_;
  count_wait_locked(*waiting_since);
  if (!error.empty()) {
    if (fault_fd_ >= 0) ::madvise(base_ + offset, page_bytes_, MADV_DONTNEED);  // what part of it came in
    free_slots_.push_back(slot);
    slot_of_[page].store(kNone, std::memory_order_relaxed);
  } else {
    slot_of_[page].store(slot, std::memory_order_relaxed);
    if (client_index() == prefetch_client_) prefetched_[page].store(1, std::memory_order_relaxed);
    mapped_order_.push_front(page);
    count_read_locked(page, address_offset, seconds, by_fault);
  }
  loaded_.notify_all();
  return error;
}

void FilePager::count_wait_locked(std::chrono::steady_clock::time_point since) {
  clients_[client_index()].wait_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void FilePager::count_read_locked(std::uint32_t page, std::uint64_t address_offset, double seconds, bool by_fault) {
  DiskCounters& counters = clients_[client_index()];
  ++counters.faults;
  if (by_fault) ++counters.unannounced;
  ++part_faults_[client_index() * part_names_.size() + part_of(address_offset)];
  counters.bytes_read += file_bytes_in(page);
  counters.read_seconds += seconds;
}

void FilePager::touch(const void* address) {
  if (!contains(address)) return;
  const std::uint32_t page = page_of(address);
  if (page_trace_ != nullptr) page_trace_->record(page);
  // Resident and near the LRU head: nothing to do, and no lock taken. Should the page be
  // evicted right after this check, the read it announces faults and loads it again.
  const std::uint32_t slot = slot_of_[page].load(std::memory_order_relaxed);
  if (slot < kLoading && mapped_order_.fresh(page, fresh_ticks_)) {
    count_prefetch_hit(page);
    return;
  }
  std::unique_lock lock(mutex_);
  if (std::string error = load(page, offset_of(address), lock); !error.empty()) throw std::runtime_error(error);
}

bool FilePager::handle_fault(const void* address) noexcept {
  if (!contains(address)) return false;
  std::unique_lock lock(mutex_);
  const std::string error = load(page_of(address), offset_of(address), lock, /*by_fault=*/true);
  if (!error.empty()) {
    // No exception can leave a signal handler, and the read that faulted cannot go on: say
    // what failed and stop as any failed command does (exit 1). Nothing is written after
    // this (no partial image), and a disk ray buffer's spill files, unnamed (O_TMPFILE),
    // vanish with the process.
    const std::string line = "wavetrace: " + error + "\n";
    [[maybe_unused]] const ssize_t ignored = ::write(STDERR_FILENO, line.data(), line.size());
    std::_Exit(1);
  }
  return true;
}

void FilePager::reset() {
  std::lock_guard lock(mutex_);
  while (!mapped_order_.empty()) evict_tail_locked(kMaxEvictionGroup);
  while (!frame_order_.empty()) {
    const std::uint32_t frame = frame_order_.tail;
    frame_order_.unlink(frame);
    frame_of_[page_in_frame_[frame]].store(kNone, std::memory_order_relaxed);
    prefetched_[page_in_frame_[frame]].store(0, std::memory_order_relaxed);
    page_in_frame_[frame] = kNone;
    free_frames_.push_back(frame);
  }
  for (DiskCounters& counters : clients_) counters = {};
  std::fill(part_faults_.begin(), part_faults_.end(), 0);
  prefetch_hits_.store(0, std::memory_order_relaxed);
  ray_windows_ = {};
  reads_in_flight_max_ = 0;
}

void FilePager::name_parts(std::vector<std::string> names, std::vector<FilePart> extents) {
  std::lock_guard lock(mutex_);
  std::sort(extents.begin(), extents.end(), [](const FilePart& a, const FilePart& b) { return a.offset < b.offset; });
  for (const FilePart& extent : extents) {
    if (extent.part >= names.size()) throw std::invalid_argument(fmt::format("{}: a part index out of range", path_));
  }
  names.push_back("other");
  part_names_ = std::move(names);
  parts_ = std::move(extents);
  part_faults_.assign(clients_.size() * part_names_.size(), 0);
}

std::uint32_t FilePager::part_of(std::uint64_t offset) const {
  const auto after = std::upper_bound(parts_.begin(), parts_.end(), offset,
                                      [](std::uint64_t at, const FilePart& part) { return at < part.offset; });
  if (after == parts_.begin()) return static_cast<std::uint32_t>(part_names_.size() - 1);
  const FilePart& part = *(after - 1);
  return offset - part.offset < part.bytes ? part.part : static_cast<std::uint32_t>(part_names_.size() - 1);
}

std::vector<std::uint64_t> FilePager::faults_by_part(std::size_t client) const {
  std::lock_guard lock(mutex_);
  std::vector<std::uint64_t> faults(part_names_.size(), 0);
  for (std::size_t c = 0; c < clients_.size(); ++c) {
    if (client != kAllClients && c != client) continue;
    for (std::size_t p = 0; p < faults.size(); ++p) faults[p] += part_faults_[c * faults.size() + p];
  }
  return faults;
}

void FilePager::add_ray_windows(const RayWindowCounters& windows) {
  std::lock_guard lock(mutex_);
  ray_windows_.windows += windows.windows;
  ray_windows_.distinct_pages += windows.distinct_pages;
}

RayWindowCounters FilePager::ray_windows() const {
  std::lock_guard lock(mutex_);
  return ray_windows_;
}

std::size_t FilePager::reads_in_flight_max() const {
  std::lock_guard lock(mutex_);
  return reads_in_flight_max_;
}

DiskCounters FilePager::counters(std::size_t client) const {
  std::lock_guard lock(mutex_);
  return clients_.at(client);
}

DiskCounters FilePager::total() const {
  std::lock_guard lock(mutex_);
  DiskCounters sum;
  for (const DiskCounters& c : clients_) {
    sum.faults += c.faults;
    sum.unannounced += c.unannounced;
    sum.bytes_read += c.bytes_read;
    sum.read_seconds += c.read_seconds;
    sum.wait_seconds += c.wait_seconds;
  }
  return sum;
}

}  // namespace wavetrace
