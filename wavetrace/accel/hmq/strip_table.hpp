// Tabulated triangle strip sets (HMQ §5): every way to lay out up to 14 triangles as a
// sequence of strips sorted by length, longest first, is one entry of a generated table, so
// a leaf stores only a 9-bit entry number. An entry is an integer partition of its triangle
// count; p(1) + ... + p(14) = 507 entries.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace wavetrace::hmq {

inline constexpr std::uint32_t kMaxLeafTriangles = 14;
inline constexpr std::uint32_t kStripTableBits = 9;

struct StripLayoutEntry {
  std::uint8_t triangles = 0;  // 1 .. 14
  std::uint8_t strips = 0;
  std::uint8_t slots = 0;      // vertex slots: sum over strips of (length + 2)
  std::array<std::uint8_t, kMaxLeafTriangles> strip_length{};  // longest first
  // Triangle k has the corners (slot[k], slot[k] + 1, slot[k] + 2); `flipped` is set for the
  // odd triangles of a strip, whose winding the strip reverses.
  // 16 entries, the last two always zero, so two 8-byte loads cover every triangle.
  std::array<std::uint8_t, 16> first_slot{};
  std::array<bool, kMaxLeafTriangles> flipped{};
};

class StripTable {
 public:
  // Inline, as every leaf a ray visits asks for it: a guard check, not a call.
  static const StripTable& instance() {
    static const StripTable table;
    return table;
  }

  std::size_t size() const { return entries_.size(); }
  const StripLayoutEntry& entry(std::uint32_t index) const { return entries_[index]; }
  // The entry of a sequence of strip lengths (any order); throws std::invalid_argument for
  // more than 14 triangles or a zero length.
  std::uint32_t find(std::span<const std::uint32_t> lengths) const;

 private:
  StripTable();
  std::vector<StripLayoutEntry> entries_;
};

}  // namespace wavetrace::hmq
