// Keys in parallel per held batch, one parallel sort of (key, batch, ray) entries, then
// the output batches gathered in parallel and emitted in key order. With a disk buffer, the
// sorted in-core part goes to a run instead, and a flush merges the runs by key.
#include "wavetrace/stages/zsort.hpp"

#include <bit>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <limits>
#include <queue>
#include <stdexcept>

#include <tbb/blocked_range.h>
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

  // The rays go back into the held batches in key order, the first batches filled and the
  // rest released: column by column, a column a task, each gathered into its thread's
  // scratch column and copied back. A flush holds an index and a column a thread more than
  // the buffer, where a second set of batches (120 bytes a ray) was its peak; and a column's
  // gather reads within one column, 1 MB at the default buffer, not across all of them.
  const std::size_t capacity = held_.front()->rays.capacity();
  for (const Batch* batch : held_) {
    if (batch->rays.capacity() != capacity) throw std::logic_error("zsort holds batches of different capacities");
  }
  // Each column's pass reads a ray's place as one packed index (batch above, ray below)
  // rather than its 16-byte entry: a fourth of the traffic.
  const int ray_bits = std::bit_width(capacity - 1);
  if ((std::uint64_t(held_.size()) << ray_bits) > std::numeric_limits<std::uint32_t>::max()) {
    throw std::logic_error("zsort holds more batches than a 32-bit ray index can name");
  }
  from_.resize(total);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, total), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k < range.end(); ++k) from_[k] = entries[k].batch << ray_bits | entries[k].ray;
  });
  ColumnTable table{.batches = held_.size(), .capacity = capacity, .ray_bits = ray_bits, .total = total};
  // The approximate hit made the key and nothing reads it after: it stays behind.
  const auto visit_columns = [&](std::size_t b, auto&& visit) {
    held_[b]->rays.for_each_column(visit, /*with_approx_hit=*/false, /*with_sort_key=*/sorts);
  };
  visit_columns(0, [&](const char*, void*, std::size_t bytes) { table.element_bytes.push_back(bytes); });
  table.columns.resize(table.element_bytes.size() * held_.size());
  for (std::size_t b = 0; b < held_.size(); ++b) {
    std::size_t c = 0;
    visit_columns(b, [&](const char*, void* column, std::size_t) { table.columns[c++ * held_.size() + b] = column; });
  }
  tbb::parallel_for(std::size_t{0}, table.element_bytes.size(), [&](std::size_t c) {
    UnfilledLargeArray<std::byte>& scratch = column_.local();
    if (scratch.size() < total * sizeof(std::uint64_t)) scratch.resize(total * sizeof(std::uint64_t));
    std::byte* const gathered = scratch.data();
    switch (table.element_bytes[c]) {
      case 1: gather_column<std::uint8_t>(table, c, gathered); break;
      case 2: gather_column<std::uint16_t>(table, c, gathered); break;
      case 4: gather_column<std::uint32_t>(table, c, gathered); break;
      case 8: gather_column<std::uint64_t>(table, c, gathered); break;
      default: throw std::logic_error("a ray column of an element size zsort cannot gather");
    }
  }, tbb::simple_partitioner());
  std::vector<Batch*> sorted(held_.begin(), held_.begin() + std::ptrdiff_t((total + capacity - 1) / capacity));
  for (std::size_t s = 0; s < sorted.size(); ++s) sorted[s]->rays.count = std::min(capacity, total - s * capacity);
  for (std::size_t b = sorted.size(); b < held_.size(); ++b) out.release(held_[b]);
  held_.clear();
  held_rays_ = 0;
  return sorted;
}

template <typename T>
void ZSortStage::gather_column(const ColumnTable& table, std::size_t column, std::byte* scratch) const {
  static_assert(sizeof(T) <= sizeof(std::uint64_t));
  T* const gathered = reinterpret_cast<T*>(scratch);
  void* const* const batch_columns = table.columns.data() + column * table.batches;
  const std::uint32_t ray_mask = (std::uint32_t{1} << table.ray_bits) - 1;
  for (std::size_t k = 0; k < table.total; ++k) {
    gathered[k] = static_cast<const T*>(batch_columns[from_[k] >> table.ray_bits])[from_[k] & ray_mask];
  }
  // Every value is read before any is written back: the output batches are the held ones.
  for (std::size_t begin = 0, s = 0; begin < table.total; begin += table.capacity, ++s) {
    std::memcpy(batch_columns[s], gathered + begin, (std::min(table.total, begin + table.capacity) - begin) * sizeof(T));
  }
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
