// The LRU pool as an intrusive doubly-linked list over page numbers: O(1) per touch, no
// allocation after construction. One mutex guards it; with one thread the counts are exact.
#include "wavetrace/memory/simulated_pager.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace wavetrace {

IoModel io_preset(std::string_view name) {
  if (name == "disk") return {"disk", 8e-3, 101e6};
  if (name == "nvme") return {"nvme", 80e-6, 3.5e9};
  throw std::invalid_argument("unknown I/O preset '" + std::string(name) + "' (known: disk, nvme)");
}

SimulatedPager::SimulatedPager(std::vector<std::span<const std::byte>> spans, std::size_t page_bytes, const MemoryBudget& budget,
             IoModel io, std::size_t clients)
    : page_bytes_(page_bytes), io_(std::move(io)), clients_(std::max<std::size_t>(clients, 1)) {
  if (page_bytes < 4096 || page_bytes > (std::size_t{1} << 30) || !std::has_single_bit(page_bytes)) {
    throw std::invalid_argument("page size " + std::to_string(page_bytes) +
                                " must be a power of two from 4096 bytes to 1 GiB");
  }
  page_shift_ = static_cast<unsigned>(std::countr_zero(page_bytes));
  std::sort(spans.begin(), spans.end(), [](auto a, auto b) { return a.data() < b.data(); });
  for (const auto& span : spans) {
    if (span.empty()) continue;
    Region region;
    region.begin = reinterpret_cast<std::uintptr_t>(span.data());
    region.end = region.begin + span.size();
    if (!regions_.empty() && region.begin < regions_.back().end) {
      throw std::invalid_argument("pager spans overlap");
    }
    region.first_page = static_cast<std::uint32_t>(page_size_.size());
    // Pages are counted from the span's start: a span is its own file in the paper's pool.
    for (std::size_t offset = 0; offset < span.size(); offset += page_bytes) {
      page_size_.push_back(static_cast<std::uint32_t>(std::min(page_bytes, span.size() - offset)));
    }
    world_bytes_ += span.size();
    regions_.push_back(region);
  }
  // A share counts pages, so that 100% holds every page even where spans end in short ones.
  capacity_pages_ = budget.is_share ? static_cast<std::size_t>(std::ceil(budget.share * double(page_size_.size())))
                                    : budget.bytes / page_bytes;
  capacity_pages_ = std::max<std::size_t>(1, capacity_pages_);
  previous_.assign(page_size_.size(), kNoPage);
  next_.assign(page_size_.size(), kNoPage);
  resident_.assign(page_size_.size(), 0);
}

std::uint32_t SimulatedPager::page_of(const void* address) const {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  for (const Region& region : regions_) {  // a handful of spans: a scan beats a search
    if (at >= region.begin && at < region.end) {
      return region.first_page + static_cast<std::uint32_t>((at - region.begin) >> page_shift_);
    }
  }
  return kNoPage;
}

void SimulatedPager::unlink(std::uint32_t page) {
  const std::uint32_t before = previous_[page], after = next_[page];
  (before == kNoPage ? head_ : next_[before]) = after;
  (after == kNoPage ? tail_ : previous_[after]) = before;
}

void SimulatedPager::push_front(std::uint32_t page) {
  previous_[page] = kNoPage;
  next_[page] = head_;
  (head_ == kNoPage ? tail_ : previous_[head_]) = page;
  head_ = page;
}

void SimulatedPager::touch(std::uint32_t page, std::size_t client) {
  const std::lock_guard lock(mutex_);
  ClientCounters& counters = clients_[client];
  ++counters.accesses;
  if (page == kNoPage) {
    ++outside_;
    return;
  }
  if (page == head_) return;
  if (resident_[page]) {
    unlink(page);
    push_front(page);
    return;
  }
  if (resident_count_ == capacity_pages_) {
    const std::uint32_t victim = tail_;
    unlink(victim);
    resident_[victim] = 0;
    --resident_count_;
  }
  push_front(page);
  resident_[page] = 1;
  ++resident_count_;
  ++counters.faults;
  counters.bytes_loaded += page_size_[page];
}

void SimulatedPager::add_accesses(std::uint64_t accesses, std::size_t client) {
  const std::lock_guard lock(mutex_);
  clients_[client].accesses += accesses;
}

PagerCounters SimulatedPager::counters(std::size_t client) const {
  const std::lock_guard lock(mutex_);
  const ClientCounters& counters = clients_[client];
  PagerCounters result{counters.accesses, counters.faults, counters.bytes_loaded, 0.0};
  result.simulated_io_seconds = double(counters.faults) * io_.latency_seconds +
                                (io_.bytes_per_second > 0.0 ? double(counters.bytes_loaded) / io_.bytes_per_second : 0.0);
  return result;
}

PagerCounters SimulatedPager::total() const {
  PagerCounters sum;
  for (std::size_t client = 0; client < clients_.size(); ++client) {
    const PagerCounters part = counters(client);
    sum.accesses += part.accesses;
    sum.faults += part.faults;
    sum.bytes_loaded += part.bytes_loaded;
    sum.simulated_io_seconds += part.simulated_io_seconds;
  }
  return sum;
}

std::uint64_t SimulatedPager::outside_accesses() const {
  const std::lock_guard lock(mutex_);
  return outside_;
}

}  // namespace wavetrace
