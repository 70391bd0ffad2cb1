// Keys in parallel per held batch, one parallel sort of (key, batch, ray) entries, then
// the output batches gathered in parallel and emitted in key order.
#include "wavetrace/stages/zsort.hpp"

#include <chrono>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "wavetrace/kernels/radix_sort.hpp"

namespace wavetrace {

bool ZSortStage::buffer(Batch* batch) const {
  held_.push_back(batch);
  const std::size_t now = buffered_rays_.load(std::memory_order_relaxed) + batch->rays.count;
  buffered_rays_.store(now, std::memory_order_seq_cst);
  return now >= options_.buffer_rays;
}

std::size_t ZSortStage::flush(StageOutput& out) const {
  if (held_.empty()) return 0;
  std::vector<std::size_t> first(held_.size() + 1, 0);
  for (std::size_t b = 0; b < held_.size(); ++b) first[b + 1] = first[b] + held_[b]->rays.count;
  const std::size_t total = first.back();
  std::vector<SortEntry>& entries = entries_;
  entries.resize(total);
  const bool sorts = options_.heuristic != ReorderHeuristic::none;
  tbb::parallel_for(std::size_t{0}, held_.size(), [&](std::size_t b) {
    RayBatch& rays = held_[b]->rays;
    if (sorts) compute_sort_keys(rays, options_.heuristic, options_.curve, bounds_);
    for (std::size_t i = 0; i < rays.count; ++i) {
      entries[first[b] + i] = {sorts ? rays.sort_key[i] : 0, std::uint32_t(b), std::uint32_t(i)};
    }
  });
  const auto start = std::chrono::steady_clock::now();
  // Both keep arrival order among equal keys (radix is stable, the comparison breaks ties
  // by arrival), so the output is the same on every run and with either algorithm.
  if (sorts && options_.sort == SortAlgorithm::radix) radix_sort_by_key(entries, scratch_);
  if (sorts && options_.sort == SortAlgorithm::parallel) tbb::parallel_sort(entries.begin(), entries.end());
  sort_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++flushes_;

  const std::size_t capacity = held_.front()->rays.capacity();
  std::vector<Batch*> sorted((total + capacity - 1) / capacity);
  for (Batch*& batch : sorted) batch = out.acquire();
  tbb::parallel_for(std::size_t{0}, sorted.size(), [&](std::size_t s) {
    RayBatch& rays = sorted[s]->rays;
    const std::size_t begin = s * capacity, end = std::min(total, begin + capacity);
    for (std::size_t k = begin; k < end; ++k) rays.copy_ray(k - begin, held_[entries[k].batch]->rays, entries[k].ray);
    rays.count = end - begin;
  });
  for (Batch* batch : held_) out.release(batch);
  held_.clear();
  buffered_rays_.store(0, std::memory_order_seq_cst);
  for (Batch* batch : sorted) out.emit(batch);
  return total;
}

void ZSortStage::process(Batch* batch, StageOutput& out) const {
  buffer(batch);
  flush(out);
}

}  // namespace wavetrace
