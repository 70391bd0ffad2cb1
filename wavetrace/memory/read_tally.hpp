// Reads a walk makes, counted by the world array each falls in (an accelerator's
// memory_spans, in its order: for bvh:width=8 its nodes, then its triangle blocks, then the
// face set), one row per thread: what `bench accel --reads` reports per ray, the nodes and
// leaves a walk visits.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace wavetrace {

class ReadTally {
 public:
  ReadTally(std::vector<std::span<const std::byte>> arrays, std::size_t threads)
      : arrays_(std::move(arrays)), stride_(row_stride(arrays_.size())), counts_(stride_ * threads) {}

  // One read at `address` by `thread` (a probe's read call: a node, a leaf, a vertex); a read
  // outside every array counts in the last column.
  void count(std::size_t thread, const void* address) {
    const auto* byte = static_cast<const std::byte*>(address);
    std::size_t array = 0;
    while (array < arrays_.size() &&
           !(byte >= arrays_[array].data() && byte < arrays_[array].data() + arrays_[array].size())) {
      ++array;
    }
    ++counts_[thread % (counts_.size() / stride_) * stride_ + array];
  }

  const std::vector<std::span<const std::byte>>& arrays() const { return arrays_; }
  // Per array, then one for reads outside them, summed over threads.
  std::vector<std::uint64_t> totals() const {
    std::vector<std::uint64_t> sums(arrays_.size() + 1, 0);
    for (std::size_t row = 0; row < counts_.size(); row += stride_) {
      for (std::size_t array = 0; array < sums.size(); ++array) sums[array] += counts_[row + array];
    }
    return sums;
  }

 private:
  // A row of counters per thread, padded to whole cache lines so threads never share one.
  static std::size_t row_stride(std::size_t arrays) { return (arrays + 1 + 7) / 8 * 8; }

  std::vector<std::span<const std::byte>> arrays_;
  std::size_t stride_;
  std::vector<std::uint64_t> counts_;
};

}  // namespace wavetrace
