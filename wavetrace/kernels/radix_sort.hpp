// A stable least-significant-digit radix sort of records by a 64-bit `key` member, 8 bits
// per pass, skipping the byte positions where every key agrees (the unused top bits of
// short keys): zsort's sort, since its keys are integers and its records small.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace wavetrace {

// Sorts `records` by key, keeping the input order among equal keys; `scratch` is resized
// and reused across calls.
template <typename Record>
void radix_sort_by_key(std::vector<Record>& records, std::vector<Record>& scratch) {
  if (records.size() < 2) return;
  std::uint64_t all_ones = ~std::uint64_t{0}, any_ones = 0;
  for (const Record& record : records) {
    all_ones &= record.key;
    any_ones |= record.key;
  }
  const std::uint64_t varying = all_ones ^ any_ones;
  scratch.resize(records.size());
  for (int shift = 0; shift < 64; shift += 8) {
    if (((varying >> shift) & 0xFFu) == 0) continue;
    std::array<std::size_t, 256> start{};
    for (const Record& record : records) ++start[(record.key >> shift) & 0xFFu];
    std::size_t offset = 0;
    for (std::size_t& bucket : start) offset += std::exchange(bucket, offset);
    for (const Record& record : records) scratch[start[(record.key >> shift) & 0xFFu]++] = record;
    records.swap(scratch);
  }
}

}  // namespace wavetrace
