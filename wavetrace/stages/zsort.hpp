// zsort (the reordering paper, §4.3): a ray buffer that, when full or when the chain has
// nothing more to give it, computes every buffered ray's key with the configured heuristic
// and curve, sorts the rays by key in parallel and emits them in key order. A buffering
// stage: its pipeline node (make_buffering_node) runs one call at a time.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/memory/ray_spill.hpp"
#include "wavetrace/stages/buffering_stage.hpp"
#include "wavetrace/stages/reorder_keys.hpp"

namespace wavetrace {

// radix: the stable LSD radix sort (kernels/radix_sort.hpp), one thread; parallel:
// tbb::parallel_sort. Radix measured faster here (docs/reordering.md), so it is the default.
enum class SortAlgorithm { radix, parallel };

// memory: the buffer is `buffer_rays` in memory, sorted and emitted whenever it fills.
// disk (the paper's, §4): `buffer_rays` is the in-core part; when it fills, its rays are
// sorted and written to a run on disk (memory/ray_spill.hpp), and once every live ray waits
// in the buffer the whole generation (the in-core part and every run) is merged by key and
// emitted as the flight budget makes room.
enum class RayBufferKind { memory, disk };
RayBufferKind parse_ray_buffer_kind(const std::string& text);
std::string to_string(RayBufferKind kind);

struct ZSortOptions {
  ReorderHeuristic heuristic = ReorderHeuristic::none;
  CurveKind curve = CurveKind::morton;
  std::size_t buffer_rays = std::size_t{1} << 18;
  SortAlgorithm sort = SortAlgorithm::radix;
  RayBufferKind buffer = RayBufferKind::memory;
  std::string spill_dir;  // disk: where runs are written (empty: the system's temporary directory)
  bool operator==(const ZSortOptions&) const = default;
};

// A buffered ray's place and key; arrival order is (batch, ray).
struct SortEntry {
  std::uint64_t key;
  std::uint32_t batch;
  std::uint32_t ray;
  bool operator<(const SortEntry& other) const {
    if (key != other.key) return key < other.key;
    if (batch != other.batch) return batch < other.batch;
    return ray < other.ray;
  }
};

class ZSortStage final : public BufferingStage {
 public:
  // What one buffered ray holds, from the batch's column lists: its ray columns with the
  // approximate hit and key, its hit columns (the buffer holds whole batches) and its sort
  // entry: 56 + 12 + 8 + 44 + 16 = 136 bytes.
  static constexpr std::size_t kBytesPerBufferedRay = RayBatch::kBytesPerRay + RayBatch::kApproxHitBytesPerRay +
                                                      RayBatch::kSortKeyBytesPerRay + HitBatch::kBytesPerHit +
                                                      sizeof(SortEntry);

  ZSortStage(const ZSortOptions& options, const Bounds3& scene_bounds);
  std::string name() const override { return "zsort"; }
  // Outside the pipeline's zsort node (a hand-wired chain): sorts one batch on its own.
  void process(Batch* batch, StageOutput& out) const override;

  ~ZSortStage() override;

  // Holds the batch; true when the buffer (its in-core part, with a disk buffer) is full.
  bool buffer(Batch* batch) const;
  // Holds the batch; once the buffer is full, sorts and emits it (memory) or writes it to a
  // run on disk (disk).
  std::size_t take(Batch* batch, StageOutput& out) const override;
  // Sorts and emits every buffered ray in key order through `out` (acquiring batches from
  // it and releasing the buffered ones); returns the rays emitted. With runs on disk it
  // starts draining instead: drain emits the merged stream.
  std::size_t flush(StageOutput& out) const override;
  std::size_t buffered_rays() const override { return buffered_rays_.load(std::memory_order_seq_cst); }
  std::size_t spilled_rays() const override { return spilled_rays_.load(std::memory_order_seq_cst); }
  bool draining() const override { return draining_.load(std::memory_order_seq_cst); }
  std::size_t drain(StageOutput& out, std::size_t max_rays) const override;
  double sort_seconds() const { return sort_seconds_; }  // sorting alone, summed over flushes
  std::size_t flushes() const { return flushes_; }
  const SpillCounters& spill() const { return spill_; }
  const ZSortOptions& options() const { return options_; }

 private:
  // The held batches' rays in key order, in the first of the held batches (full; the others
  // released to `out`); arrival order among equal keys.
  std::vector<Batch*> sort_held(StageOutput& out) const;
  // The held batches' ray columns, column-major (columns[column * batches + batch]).
  struct ColumnTable {
    std::size_t batches = 0, capacity = 0;
    int ray_bits = 0;       // from_'s packing: batch << ray_bits | ray
    std::size_t total = 0;  // rays held
    std::vector<std::size_t> element_bytes;
    std::vector<void*> columns;
  };
  // Column `column` of the held rays in from_'s order, written into the first held batches.
  template <typename T>
  void gather_column(const ColumnTable& table, std::size_t column, std::byte* scratch) const;
  // Writes the in-core part, sorted, as one more run of the next generation.
  void spill_held(StageOutput& out) const;
  struct Merge;  // the runs of the generation being drained, merged by (key, run)

  ZSortOptions options_;
  Bounds3 bounds_;
  std::string spill_dir_;
  mutable std::vector<Batch*> held_;
  mutable std::size_t held_rays_ = 0;
  mutable LargeArray<SortEntry> entries_, scratch_;  // kept across flushes, on huge pages: few page faults
  // A thread's ray column in key order, kept across flushes: bytes, storage for values of any
  // column's type (8 bytes at most).
  mutable tbb::enumerable_thread_specific<UnfilledLargeArray<std::byte>> column_;
  mutable UnfilledLargeArray<std::uint32_t> from_;  // the held ray each place in key order takes, packed
  mutable std::atomic<std::size_t> buffered_rays_{0}, spilled_rays_{0};
  mutable std::atomic<bool> draining_{false};
  mutable std::vector<std::unique_ptr<SpillRun>> runs_;  // the next generation's
  mutable std::unique_ptr<Merge> merge_;
  mutable SpillCounters spill_;
  mutable double sort_seconds_ = 0.0;
  mutable std::size_t flushes_ = 0;
};

}  // namespace wavetrace
