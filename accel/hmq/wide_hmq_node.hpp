// The 8-wide layout of HMQ (`hmq:width=8`): the paper's leaves and global grid under 64-byte
// nodes of eight children, each child box quantized to 8 bits per plane against the node's
// own box as its parent decoded it (the frame), as compressed wide BVHs (Ylitie, Karras and
// Laine 2017) and Embree's quantized nodes do, but with no float frame stored: the frame
// travels down the traversal stack, as HMQ's 4-bit binary nodes do.
#pragma once

#include <cmath>
#include <cstdint>

#include "accel/hmq/hmq_format.hpp"

namespace wavetrace::hmq {

// WideHmqNode, 64 bytes, 64-byte aligned (one cache line). Children sit in slots 0..7; with
// F = the frame (the node's decoded box) and step = (F.upper - F.lower) * (1.0f / 255.0f) per
// axis, in floats, child k's box is
//   lower = fma(q_lower[k], step, F.lower)      upper = fma(-q_upper[k], step, F.upper)
// (fused multiply-adds, one rounding each; the encoder rounds q outward through this very
// arithmetic, so the decoded box always holds the child's triangles).
//
//   offset  size  field
//        0     8  lower_x[8]   uint8  q_lower of each slot's x
//        8     8  upper_x[8]   uint8  q_upper of each slot's x
//       16    16  lower_y, upper_y    the same for y
//       32    16  lower_z, upper_z    the same for z
//       48     4  child_base   uint32 node index of the first inner child; the node's inner
//                                     children are nodes child_base, child_base + 1, ... in
//                                     slot order
//       52     4  leaf_base    uint32 offset in 2-byte units in the leaf array of the first leaf
//                                     child's record; the others follow in slot order
//       56     8  meta[8]      uint8  0: empty slot; 255: inner child; 1 .. 254: leaf child
//                                     whose record takes that many 2-byte units
// A leaf record (hmq_format.hpp, unchanged) starts 2-byte aligned and is zero-padded to an
// even size (at most 472 bytes: 14 triangles, 42 vertices of 3 x 25 bits, 32-bit id deltas);
// its grid box is its decoded box snapped outward, as in the binary layout.
// Slots are filled from 0 in the collapse's order; traversal sorts the entered children by
// distance. (Ylitie et al.'s octant slots, visited without sorting, cost 10% on primary rays
// of room:1M: 13% more nodes and 33% more leaves visited.)
struct alignas(64) WideHmqNode {
  static constexpr int kWidth = 8;
  static constexpr std::uint8_t kInnerMeta = 255;
  static constexpr std::uint32_t kLeafUnitBytes = 2;
  static constexpr std::uint32_t kMaxLeafUnits = 254;
  std::uint8_t lower_x[kWidth], upper_x[kWidth];
  std::uint8_t lower_y[kWidth], upper_y[kWidth];
  std::uint8_t lower_z[kWidth], upper_z[kWidth];
  std::uint32_t child_base;
  std::uint32_t leaf_base;
  std::uint8_t meta[kWidth];

  const std::uint8_t* lower(int axis) const { return reinterpret_cast<const std::uint8_t*>(this) + 16 * axis; }
  const std::uint8_t* upper(int axis) const { return reinterpret_cast<const std::uint8_t*>(this) + 16 * axis + 8; }
  std::uint8_t* lower(int axis) { return reinterpret_cast<std::uint8_t*>(this) + 16 * axis; }
  std::uint8_t* upper(int axis) { return reinterpret_cast<std::uint8_t*>(this) + 16 * axis + 8; }
};
static_assert(sizeof(WideHmqNode) == 64, "the wide HMQ node is one cache line");

inline float frame_step(const Box& frame, int axis) { return (frame.upper[axis] - frame.lower[axis]) * (1.0f / 255.0f); }

// Slot `slot`'s box, one lane of what traversal computes for all eight (bit-identical).
inline Box decode_wide_child(const WideHmqNode& node, int slot, const Box& frame) {
  Box child;
  for (int axis = 0; axis < 3; ++axis) {
    const float step = frame_step(frame, axis);
    child.lower[axis] = std::fma(float(node.lower(axis)[slot]), step, frame.lower[axis]);
    child.upper[axis] = std::fma(-float(node.upper(axis)[slot]), step, frame.upper[axis]);
  }
  return child;
}

}  // namespace wavetrace::hmq
