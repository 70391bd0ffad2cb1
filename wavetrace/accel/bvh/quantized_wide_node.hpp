// The 8-wide quantized node that HMQ and Ray-Strips put above their compact leaves
// (`hmq:width=8`, `raystrips:width=8`): eight child boxes at 8 bits a plane against the node's
// own box as its parent decoded it (its frame), as compressed wide BVHs (Ylitie, Karras and
// Laine 2017) and Embree's quantized nodes do, but with no float frame stored: the frame
// travels down the traversal stack, as HMQ's 4-bit binary nodes do.
#pragma once

#include <cmath>
#include <cstdint>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// QuantizedWideNode, 64 bytes, 64-byte aligned (one cache line). Children sit in slots 0..7;
// with F = the frame and step = (F.upper - F.lower) * (1.0f / 255.0f) per axis, in floats,
// child k's box is
//   lower = fma(q_lower[k], step, F.lower)      upper = fma(-q_upper[k], step, F.upper)
// (fused multiply-adds, one rounding each; the encoder rounds q outward through this very
// arithmetic, so a decoded box always holds its child's whole content). The root's frame is
// the binary tree's root box, stored by the owner.
//
//   offset  size  field
//        0     8  lower_x[8]   uint8  q_lower of each slot's x
//        8     8  upper_x[8]   uint8  q_upper of each slot's x
//       16    16  lower_y, upper_y    the same for y
//       32    16  lower_z, upper_z    the same for z
//       48     4  child_base   uint32 node index of the first inner child; the node's inner
//                                     children are nodes child_base, child_base + 1, ... in
//                                     slot order
//       52     4  leaf_base    uint32 leaf reference of the first leaf child
//       56     8  meta[8]      uint8  0: empty slot; 255: inner child; 1 .. 254: leaf child of
//                                     that weight. A leaf child's reference is leaf_base plus
//                                     the weights of the leaf slots before it: its record's
//                                     offset in 2-byte units for HMQ, its number for Ray-Strips.
// Slots are filled from 0; traversal sorts the entered children by distance. (Ylitie et al.'s
// octant slots, visited without sorting, cost 10% on primary rays of room:1M with HMQ's
// leaves: 13% more nodes and 33% more leaves visited.)
struct alignas(64) QuantizedWideNode {
  static constexpr int kWidth = 8;
  static constexpr std::uint8_t kInnerMeta = 255;
  static constexpr std::uint32_t kMaxLeafWeight = 254;
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
static_assert(sizeof(QuantizedWideNode) == 64, "the quantized wide node is one cache line");

inline float frame_step(const Bounds3& frame, int axis) {
  return (frame.upper[axis] - frame.lower[axis]) * (1.0f / 255.0f);
}

// Slot `slot`'s box, one lane of what traversal computes for all eight (bit-identical).
inline Bounds3 decode_wide_child(const QuantizedWideNode& node, int slot, const Bounds3& frame) {
  Bounds3 child;
  for (int axis = 0; axis < 3; ++axis) {
    const float step = frame_step(frame, axis);
    child.lower[axis] = std::fma(float(node.lower(axis)[slot]), step, frame.lower[axis]);
    child.upper[axis] = std::fma(-float(node.upper(axis)[slot]), step, frame.upper[axis]);
  }
  return child;
}

}  // namespace wavetrace
