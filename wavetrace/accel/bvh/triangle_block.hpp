// The 8-wide BVH's leaf triangles, four to a block with their corners in SSE lanes, so one
// 4-lane watertight test (watertight_lanes.hpp) answers a leaf of up to four triangles from
// two and a half cache lines, without reading a leaf index, an index triple or a vertex (two
// consecutive blocks' rows make one 8-lane test).
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "wavetrace/kernels/watertight_lanes.hpp"

namespace wavetrace {

// TriangleBlock, 160 bytes, 32-byte aligned (saved as section "bvh8.triangle_blocks"):
//
//   offset  size  field
//        0   144  corner   float[3][3][4]: corner c (0..2), axis a (x, y, z), lane k at byte
//                          4 * (12 c + 4 a + k); the corners in the face set's winding
//      144    16  slot[4]  uint32: lane k's triangle, a face-set slot (its input id through the
//                          face set's id map)
//
// A leaf of n triangles (1..16) is ceil(n / 4) consecutive blocks, its triangles in SAH leaf
// order; lanes past n in the last block are unused: corners 0, slot 0, never reported.
struct alignas(32) TriangleBlock {
  static constexpr std::uint32_t kLanes = 4;
  TriangleLanes<kLanes> corners;
  std::uint32_t slot[kLanes];

  glm::vec3 corner(std::uint32_t lane, int c) const {
    return {corners.corner[c][0][lane], corners.corner[c][1][lane], corners.corner[c][2][lane]};
  }
  static std::uint32_t blocks_for(std::uint32_t triangles) { return (triangles + kLanes - 1) / kLanes; }
};
static_assert(sizeof(TriangleBlock) == 160, "a triangle block is 160 bytes");

}  // namespace wavetrace
