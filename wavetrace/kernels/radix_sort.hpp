// A stable least-significant-digit radix sort of records by a 64-bit `key` member, 11 bits
// per pass, skipping the digits where every key agrees (the unused top bits of short keys):
// zsort's sort, since its keys are integers and its records small. Large arrays are cut into
// blocks that count and scatter in parallel; each block writes its records to its own ranges
// of the buckets, blocks in order, so the sort stays stable.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace wavetrace {

// Sorts `records` (a std::vector of records, any allocator) by key, keeping the input order
// among equal keys; `scratch` is resized and reused across calls.
template <typename Records>
void radix_sort_by_key(Records& records, Records& scratch) {
  using Record = typename Records::value_type;
  constexpr int kDigitBits = 11;  // 6 passes for 64-bit keys (8 of 8 bits): fewer passes over the records
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  constexpr std::size_t kParallelRecords = std::size_t{1} << 16;  // below this one block: a pass is microseconds
  const std::size_t n = records.size();
  if (n < 2) return;
  std::uint64_t all_ones = ~std::uint64_t{0}, any_ones = 0;
  for (const Record& record : records) {
    all_ones &= record.key;
    any_ones |= record.key;
  }
  const std::uint64_t varying = all_ones ^ any_ones;
  const std::size_t blocks =
      n < kParallelRecords ? 1
                           : std::min<std::size_t>(n / (kParallelRecords / 4),
                                                   4 * std::size_t(tbb::this_task_arena::max_concurrency()));
  const auto block_begin = [&](std::size_t b) { return n * b / blocks; };
  scratch.resize(n);
  // counts[b][d]: records of block b with digit d; then where block b writes its next one.
  std::vector<std::array<std::size_t, kBuckets>> counts(blocks);
  for (int shift = 0; shift < 64; shift += kDigitBits) {
    if (((varying >> shift) & (kBuckets - 1)) == 0) continue;
    const auto digit = [shift](const Record& record) { return (record.key >> shift) & (kBuckets - 1); };
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
      counts[b].fill(0);
      for (std::size_t i = block_begin(b), end = block_begin(b + 1); i < end; ++i) ++counts[b][digit(records[i])];
    });
    std::size_t offset = 0;
    for (std::size_t d = 0; d < kBuckets; ++d) {
      for (std::size_t b = 0; b < blocks; ++b) offset += std::exchange(counts[b][d], offset);
    }
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
      std::array<std::size_t, kBuckets>& next = counts[b];
      for (std::size_t i = block_begin(b), end = block_begin(b + 1); i < end; ++i) {
        scratch[next[digit(records[i])]++] = records[i];
      }
    });
    records.swap(scratch);
  }
}

}  // namespace wavetrace
