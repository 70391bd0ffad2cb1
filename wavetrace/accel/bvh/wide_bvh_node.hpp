// The 8-wide variant's node: the binary SAH tree collapsed so one node holds up to eight
// children, whose boxes one AVX2 instruction sequence tests together.
#pragma once

#include <cstdint>

namespace wavetrace {

// WideBvhNode, 256 bytes, 64-byte aligned (four cache lines), children in SIMD lanes:
//
//   offset  size  field
//        0    32  lower_x[8]  float   child box minimum x, lane k = child k
//       32    32  upper_x[8]  float
//       64    32  lower_y[8]  float
//       96    32  upper_y[8]  float
//      128    32  lower_z[8]  float
//      160    32  upper_z[8]  float
//      192    32  child[8]    uint32  inner child: index of its node; leaf child: its first
//                                     triangle block (triangle_block.hpp), ceil(count / 4) of them
//      224     8  count[8]    uint8   0: inner child; 1..16: leaf with that many triangles
//      232    24  (padding)
//
// An unused lane has every bound +inf: its slab interval is empty for every ray
// direction, so it is never entered (and count 0, child 0 are never read).
struct alignas(64) WideBvhNode {
  static constexpr int kWidth = 8;
  float lower_x[kWidth], upper_x[kWidth];
  float lower_y[kWidth], upper_y[kWidth];
  float lower_z[kWidth], upper_z[kWidth];
  std::uint32_t child[kWidth];
  std::uint8_t count[kWidth];
  std::uint8_t padding[24];
};
static_assert(sizeof(WideBvhNode) == 256, "the wide node is 256 bytes");

}  // namespace wavetrace
