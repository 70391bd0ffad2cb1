// Keys in parallel per held batch, one parallel sort of (key, batch, ray) entries, then
// the output batches gathered in parallel and emitted in key order. With a disk buffer, the
// sorted in-core part goes to a run instead, and a flush merges the runs by key.
#include "wavetrace/stages/zsort.hpp"

#include <chrono>
#include <filesystem>
#include <queue>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "wavetrace/kernels/radix_sort.hpp"

namespace wavetrace {

RayBufferKind parse_ray_buffer_kind(const std::string& text) {
  if (text == "memory") return RayBufferKind::memory;
  if (text == "disk") return RayBufferKind::disk;
  throw std::invalid_argument("unknown ray buffer '" + text + "' (memory, disk)");
}

std::string to_string(RayBufferKind kind) { return kind == RayBufferKind::disk ? "disk" : "memory"; }

// The generation being drained: each run's current block and position, and a heap of the
// runs by their next ray's (key, run index): the run index breaks ties, and runs were
// written in arrival order, so equal keys leave in arrival order, as from one in-core sort.
struct ZSortStage::Merge {
  struct Head {
    std::uint64_t key;
    std::size_t run;
    bool operator>(const Head& other) const { return key != other.key ? key > other.key : run > other.run; }
  };
  std::vector<std::unique_ptr<SpillRun>> runs;
  std::vector<Batch*> blocks;
  std::vector<std::size_t> positions;
  std::priority_queue<Head, std::vector<Head>, std::greater<Head>> heads;

  static std::uint64_t key_of(const RayBatch& rays, std::size_t i) { return rays.has_sort_key() ? rays.sort_key[i] : 0; }
  // Reads the run's next block; false at its end.
  bool refill(std::size_t run) {
    positions[run] = 0;
    return runs[run]->read_block(blocks[run]->rays);
  }
};

ZSortStage::ZSortStage(const ZSortOptions& options, const Bounds3& scene_bounds)
    : options_(options),
      bounds_(scene_bounds),
      spill_dir_(options.spill_dir.empty() ? std::filesystem::temp_directory_path().string() : options.spill_dir) {}

ZSortStage::~ZSortStage() = default;

bool ZSortStage::buffer(Batch* batch) const {
  held_.push_back(batch);
  held_rays_ += batch->rays.count;
  buffered_rays_.store(buffered_rays_.load(std::memory_order_relaxed) + batch->rays.count, std::memory_order_seq_cst);
  return held_rays_ >= options_.buffer_rays;
}

std::size_t ZSortStage::take(Batch* batch, StageOutput& out) const {
  if (!buffer(batch)) return 0;
  if (options_.buffer == RayBufferKind::memory) return flush(out);
  spill_held(out);
  return 0;
}

std::vector<Batch*> ZSortStage::sort_held(StageOutput& out) const {
  std::vector<std::size_t> first(held_.size() + 1, 0);
  for (std::size_t b = 0; b < held_.size(); ++b) first[b + 1] = first[b] + held_[b]->rays.count;
  const std::size_t total = first.back();
  LargeArray<SortEntry>& entries = entries_;
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

  const std::size_t capacity = held_.front()->rays.capacity();
  std::vector<Batch*> sorted((total + capacity - 1) / capacity);
  for (Batch*& batch : sorted) batch = out.acquire();
  tbb::parallel_for(std::size_t{0}, sorted.size(), [&](std::size_t s) {
    RayBatch& rays = sorted[s]->rays;
    const std::size_t begin = s * capacity, end = std::min(total, begin + capacity);
    for (std::size_t k = begin; k < end; ++k) rays.copy_keyed_ray(k - begin, held_[entries[k].batch]->rays, entries[k].ray);
    rays.count = end - begin;
  });
  for (Batch* batch : held_) out.release(batch);
  held_.clear();
  held_rays_ = 0;
  return sorted;
}

void ZSortStage::spill_held(StageOutput& out) const {
  if (held_.empty()) return;
  const std::vector<Batch*> sorted = sort_held(out);
  auto run = std::make_unique<SpillRun>(spill_dir_, spill_);
  try {
    for (Batch* batch : sorted) run->append(batch->rays);
    run->finish_writing();
  } catch (...) {
    for (Batch* batch : sorted) out.release(batch);
    throw;
  }
  spilled_rays_.fetch_add(run->rays(), std::memory_order_seq_cst);
  for (Batch* batch : sorted) out.release(batch);
  runs_.push_back(std::move(run));
}

std::size_t ZSortStage::flush(StageOutput& out) const {
  if (draining()) return 0;
  if (runs_.empty()) {
    // Everything is in core: one sort, emitted at once (the memory buffer's flush).
    if (held_.empty()) return 0;
    const std::vector<Batch*> sorted = sort_held(out);
    std::size_t total = 0;
    for (Batch* batch : sorted) total += batch->rays.count;
    ++flushes_;
    buffered_rays_.store(0, std::memory_order_seq_cst);
    for (Batch* batch : sorted) out.emit(batch);
    return total;
  }
  // The whole generation: the in-core part becomes the last run, then every run is merged.
  spill_held(out);
  ++flushes_;
  merge_ = std::make_unique<Merge>();
  merge_->runs = std::move(runs_);
  runs_.clear();
  merge_->blocks.resize(merge_->runs.size());
  merge_->positions.resize(merge_->runs.size());
  for (std::size_t r = 0; r < merge_->runs.size(); ++r) {
    merge_->blocks[r] = out.acquire();
    if (merge_->refill(r)) merge_->heads.push({Merge::key_of(merge_->blocks[r]->rays, 0), r});
  }
  buffered_rays_.store(0, std::memory_order_seq_cst);
  draining_.store(true, std::memory_order_seq_cst);
  return 0;
}

std::size_t ZSortStage::drain(StageOutput& out, std::size_t max_rays) const {
  if (!draining()) return 0;
  Merge& merge = *merge_;
  std::size_t emitted = 0;
  while (!merge.heads.empty() && (emitted == 0 || emitted < max_rays)) {
    Batch* batch = out.acquire();
    RayBatch& rays = batch->rays;
    std::size_t count = 0;
    while (count < rays.capacity() && !merge.heads.empty()) {
      const std::size_t run = merge.heads.top().run;
      merge.heads.pop();
      RayBatch& block = merge.blocks[run]->rays;
      rays.copy_keyed_ray(count++, block, merge.positions[run]);
      if (++merge.positions[run] < block.count || merge.refill(run)) {
        merge.heads.push({Merge::key_of(block, merge.positions[run]), run});
      }
    }
    rays.count = count;
    emitted += count;
    spilled_rays_.fetch_sub(count, std::memory_order_seq_cst);
    out.emit(batch);
  }
  if (merge.heads.empty()) {
    for (Batch* block : merge.blocks) out.release(block);
    merge_.reset();  // closes the runs: their files are gone
    draining_.store(false, std::memory_order_seq_cst);
  }
  return emitted;
}

void ZSortStage::process(Batch* batch, StageOutput& out) const {
  buffer(batch);
  flush(out);
  while (draining()) drain(out, std::size_t(-1));
}

}  // namespace wavetrace
