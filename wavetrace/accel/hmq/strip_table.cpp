// Generates the strip-set table: partitions of 1 .. 14, parts in non-increasing order.
#include "wavetrace/accel/hmq/strip_table.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <stdexcept>

namespace wavetrace::hmq {
namespace {

std::uint64_t key_of(std::vector<std::uint32_t> lengths) {
  std::sort(lengths.begin(), lengths.end(), std::greater<>());
  std::uint64_t key = 0;
  for (const std::uint32_t length : lengths) key = key * 16 + length;  // lengths <= 14 < 16
  return key * 16 + lengths.size();
}

const std::map<std::uint64_t, std::uint32_t>& index_by_key(const std::vector<StripLayoutEntry>& entries) {
  static const std::map<std::uint64_t, std::uint32_t> index = [&] {
    std::map<std::uint64_t, std::uint32_t> map;
    for (std::uint32_t i = 0; i < entries.size(); ++i) {
      const StripLayoutEntry& e = entries[i];
      map.emplace(key_of({e.strip_length.begin(), e.strip_length.begin() + e.strips}), i);
    }
    return map;
  }();
  return index;
}

}  // namespace

StripTable::StripTable() {
  std::vector<std::uint32_t> parts;
  // Every partition of `remaining` with parts no larger than `largest`, appended to `parts`.
  std::function<void(std::uint32_t, std::uint32_t)> partitions = [&](std::uint32_t remaining, std::uint32_t largest) {
    if (remaining == 0) {
      StripLayoutEntry entry;
      std::uint32_t slot = 0, triangle = 0;
      for (const std::uint32_t length : parts) {
        entry.strip_length[entry.strips++] = static_cast<std::uint8_t>(length);
        for (std::uint32_t k = 0; k < length; ++k, ++triangle) {
          entry.first_slot[triangle] = static_cast<std::uint8_t>(slot + k);
          entry.flipped[triangle] = (k % 2) == 1;
        }
        slot += length + 2;
      }
      entry.triangles = static_cast<std::uint8_t>(triangle);
      entry.slots = static_cast<std::uint8_t>(slot);
      entries_.push_back(entry);
      return;
    }
    for (std::uint32_t part = std::min(remaining, largest); part >= 1; --part) {
      parts.push_back(part);
      partitions(remaining - part, part);
      parts.pop_back();
    }
  };
  for (std::uint32_t total = 1; total <= kMaxLeafTriangles; ++total) partitions(total, total);
}

std::uint32_t StripTable::find(std::span<const std::uint32_t> lengths) const {
  std::uint32_t total = 0;
  for (const std::uint32_t length : lengths) {
    if (length == 0) throw std::invalid_argument("hmq: a strip of no triangles");
    total += length;
  }
  if (total == 0 || total > kMaxLeafTriangles) throw std::invalid_argument("hmq: a leaf holds 1 .. 14 triangles");
  return index_by_key(entries_).at(key_of({lengths.begin(), lengths.end()}));
}

}  // namespace wavetrace::hmq
