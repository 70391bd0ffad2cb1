// zsort (the reordering paper, §4.3): a ray buffer that, when full or when the chain has
// nothing more to give it, computes every buffered ray's key with the configured heuristic
// and curve, sorts the rays by key in parallel and emits them in key order. A buffering
// stage: its pipeline node (make_buffering_node) runs one call at a time.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "wavetrace/stages/reorder_keys.hpp"
#include "wavetrace/stages/buffering_stage.hpp"

namespace wavetrace {

// radix: the stable LSD radix sort (kernels/radix_sort.hpp), one thread; parallel:
// tbb::parallel_sort. Radix measured faster here (docs/reordering.md), so it is the default.
enum class SortAlgorithm { radix, parallel };

struct ZSortOptions {
  ReorderHeuristic heuristic = ReorderHeuristic::none;
  CurveKind curve = CurveKind::morton;
  std::size_t buffer_rays = std::size_t{1} << 18;
  SortAlgorithm sort = SortAlgorithm::radix;
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

  ZSortStage(const ZSortOptions& options, const Bounds3& scene_bounds) : options_(options), bounds_(scene_bounds) {}
  std::string name() const override { return "zsort"; }
  // Outside the pipeline's zsort node (a hand-wired chain): sorts one batch on its own.
  void process(Batch* batch, StageOutput& out) const override;

  // Holds the batch; true when the buffer is full.
  bool buffer(Batch* batch) const;
  // Holds the batch, and sorts and emits the buffer once it is full.
  std::size_t take(Batch* batch, StageOutput& out) const override { return buffer(batch) ? flush(out) : 0; }
  // Sorts and emits every buffered ray in key order through `out` (acquiring batches from
  // it and releasing the buffered ones); returns the rays emitted.
  std::size_t flush(StageOutput& out) const override;
  std::size_t buffered_rays() const override { return buffered_rays_.load(std::memory_order_seq_cst); }
  double sort_seconds() const { return sort_seconds_; }  // sorting alone, summed over flushes
  std::size_t flushes() const { return flushes_; }
  const ZSortOptions& options() const { return options_; }

 private:
  ZSortOptions options_;
  Bounds3 bounds_;
  mutable std::vector<Batch*> held_;
  mutable std::vector<SortEntry> entries_, scratch_;  // kept across flushes: no page faults per flush
  mutable std::atomic<std::size_t> buffered_rays_{0};
  mutable double sort_seconds_ = 0.0;
  mutable std::size_t flushes_ = 0;
};

}  // namespace wavetrace
