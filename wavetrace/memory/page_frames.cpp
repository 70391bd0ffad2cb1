// The real pager's frames (file_pager.hpp, "Frames"): pages read straight into buffers of
// fixed address, pinned by the walks that read them there, reused least recently used first.
#include "wavetrace/memory/file_pager.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <optional>
#include <stdexcept>

#include <sys/mman.h>

#include <fmt/format.h>

#include "wavetrace/memory/cache_aligned_allocator.hpp"  // kHugePageBytes, huge_pages_advised
#include "wavetrace/memory/page_trace.hpp"

namespace wavetrace {

bool FilePager::use_frames(bool wanted) {
  std::lock_guard lock(mutex_);
  if (!mapped_order_.empty() || !frame_order_.empty() || reads_in_flight_ > 0) {
    throw std::logic_error(fmt::format("{}: frames switched while pages are resident", path_));
  }
  release_frames();
  size_mapped_pool_locked(budget_pages_);
  if (!wanted || page_bytes_ < kMinFramePageBytes) return false;
  const std::size_t mapped = std::clamp<std::size_t>(budget_pages_ / kMappedPoolShare, 2, kMappedPoolMaxPages);
  const std::size_t stride = page_bytes_ + kFrameTailBytes;
  const std::size_t frames = budget_pages_ > mapped ? (budget_pages_ - mapped) * page_bytes_ / stride : 0;
  if (frames < kMinFrames) return false;
  // On 2 MiB pages where the system allows: fewer TLB misses for the walks that read there,
  // and every 4 KiB of the frames made present now, once, not at each one's first read.
  const std::size_t bytes = (frames * stride + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  frames_ = map_aligned(bytes, kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS);
  if (frames_ == nullptr) {
    throw std::runtime_error(fmt::format("{}: cannot allocate {} frames of {} bytes: {}", path_, frames, stride,
                                         std::strerror(errno)));
  }
  frames_bytes_ = bytes;
  if (huge_pages_advised()) ::madvise(frames_, bytes, MADV_HUGEPAGE);  // advice only
  ::madvise(frames_, bytes, MADV_POPULATE_WRITE);  // where the kernel has it; else each 4 KiB at its first read
  frame_stride_ = stride;
  frame_count_ = frames;
  if (frame_of_ == nullptr) {
    frame_of_ = std::make_unique<std::atomic<std::uint32_t>[]>(page_count_);
    for (std::size_t p = 0; p < page_count_; ++p) frame_of_[p].store(kNone, std::memory_order_relaxed);
  }
  pins_ = std::make_unique<std::atomic<std::uint32_t>[]>(frames);
  page_in_frame_.assign(frames, kNone);
  frame_order_.reset(frames);
  free_frames_.clear();
  for (std::size_t f = frames; f-- > 0;) free_frames_.push_back(static_cast<std::uint32_t>(f));
  frame_fresh_ticks_ = std::max<std::uint64_t>(frames / 4, 1);
  size_mapped_pool_locked(mapped);
  return true;
}

void FilePager::release_frames() {
  if (frames_ != nullptr) ::munmap(frames_, frames_bytes_);
  frames_ = nullptr;
  frames_bytes_ = frame_stride_ = frame_count_ = 0;
  free_frames_.clear();
  frame_order_.reset(0);
}

bool FilePager::evict_frame_locked() {
  // A pinned frame is passed over and put at the head, as read now: once round the list
  // finds every frame pinned.
  for (std::size_t tries = 0; tries < frame_count_ && !frame_order_.empty(); ++tries) {
    const std::uint32_t frame = frame_order_.tail, page = page_in_frame_[frame];
    frame_order_.unlink(frame);
    frame_of_[page].store(kNone, std::memory_order_seq_cst);
    if (pins_[frame].load(std::memory_order_seq_cst) != 0) {
      frame_of_[page].store(frame, std::memory_order_seq_cst);
      frame_order_.push_front(frame);
      continue;
    }
    page_in_frame_[frame] = kNone;
    prefetched_[page].store(0, std::memory_order_relaxed);
    free_frames_.push_back(frame);
    return true;
  }
  return false;
}

std::uint32_t FilePager::load_frame(std::uint32_t page, std::uint64_t address_offset, std::unique_lock<std::mutex>& lock) {
  std::optional<std::chrono::steady_clock::time_point> waiting_since;
  for (;;) {
    const std::uint32_t state = frame_of_[page].load(std::memory_order_relaxed);
    if (state != kNone) count_prefetch_hit(page);
    if (state != kNone && state != kLoading) {
      frame_order_.move_to_front(state);
      if (waiting_since) count_wait_locked(*waiting_since);
      return state;
    }
    if (!waiting_since) waiting_since = std::chrono::steady_clock::now();
    if (state == kLoading) {  // another thread reads this page
      loaded_.wait(lock);
      continue;
    }
    break;
  }
  if (free_frames_.empty() && !evict_frame_locked()) return kNone;
  const std::uint32_t frame = free_frames_.back();
  free_frames_.pop_back();
  frame_of_[page].store(kLoading, std::memory_order_relaxed);
  reads_in_flight_max_ = std::max(reads_in_flight_max_, ++reads_in_flight_);
  lock.unlock();

  // Straight into the frame: no buffer, no copy. A frame taken off the free list holds no
  // pin but a fast-path reader's passing one, which finds the page gone and lets go.
  double seconds = 0.0;
  const std::string error = read_page(page, frame_bytes(frame), frame_stride_, seconds);

  lock.lock();
  --reads_in_flight_;
  count_wait_locked(*waiting_since);
  if (!error.empty()) {
    free_frames_.push_back(frame);
    frame_of_[page].store(kNone, std::memory_order_relaxed);
    loaded_.notify_all();
    throw std::runtime_error(error);
  }
  page_in_frame_[frame] = page;
  frame_of_[page].store(frame, std::memory_order_release);
  if (client_index() == prefetch_client_) prefetched_[page].store(1, std::memory_order_relaxed);
  frame_order_.push_front(frame);
  count_read_locked(page, address_offset, seconds, /*by_fault=*/false);
  loaded_.notify_all();
  return frame;
}

const std::byte* FilePager::pin(const void* address, std::uint32_t& frame) {
  if (!contains(address) || frame_count_ == 0) return nullptr;
  const std::uint32_t page = page_of(address);
  if (page_trace_ != nullptr) page_trace_->record(page);
  // Resident: pin, then make sure the page is still the frame's (an eviction between the
  // two either saw the pin and kept the page, or this check sees it gone).
  const std::uint32_t seen = frame_of_[page].load(std::memory_order_acquire);
  if (seen < kLoading) {
    pins_[seen].fetch_add(1, std::memory_order_seq_cst);
    if (frame_of_[page].load(std::memory_order_seq_cst) == seen) {
      frame = seen;
      // Near the head of the LRU order: left where it is, no lock taken (as touch does).
      if (frame_order_.fresh(seen, frame_fresh_ticks_)) {
        count_prefetch_hit(page);
        return frame_bytes(seen);
      }
      std::lock_guard lock(mutex_);  // pinned, it cannot leave its frame: only its place in the order moves
      count_prefetch_hit(page);
      frame_order_.move_to_front(seen);
      return frame_bytes(seen);
    }
    pins_[seen].fetch_sub(1, std::memory_order_relaxed);
  }
  std::unique_lock lock(mutex_);
  const std::uint32_t loaded = load_frame(page, offset_of(address), lock);
  if (loaded == kNone) return nullptr;
  pins_[loaded].fetch_add(1, std::memory_order_relaxed);  // under the lock: no eviction runs meanwhile
  frame = loaded;
  return frame_bytes(loaded);
}

}  // namespace wavetrace
