// The baseline's node: the classic uncompressed 32-byte binary BVH node that both
// compact-accelerator papers compare against.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

namespace wavetrace {

// BvhNode, 32 bytes, little-endian, two per 64-byte cache line (the array is 64-aligned):
//
//   offset  size  field
//        0    12  lower  float x, y, z   box minimum
//       12    12  upper  float x, y, z   box maximum
//       24     4  first  uint32          inner: index of the left child node
//                                        leaf:  first slot in the leaf-triangle array
//       28     4  count  uint32          inner: index of the right child node (bit 31 clear)
//                                        leaf:  0x80000000 | number of triangles (1..16)
//
// Children are addressed explicitly, so any node order (depth-first, breadth-first,
// van Emde Boas) is the same format. A leaf's triangles are leaf_triangles[first ..
// first + count), each a 32-bit index into the indexed face set (uint32 x3 per
// triangle, float x3 per vertex).
struct BvhNode {
  glm::vec3 lower;
  glm::vec3 upper;
  std::uint32_t first;
  std::uint32_t count;

  static constexpr std::uint32_t kLeafFlag = 0x80000000u;
  bool leaf() const { return (count & kLeafFlag) != 0; }
  std::uint32_t triangle_count() const { return count & ~kLeafFlag; }
  std::uint32_t left() const { return first; }
  std::uint32_t right() const { return count; }
};
static_assert(sizeof(BvhNode) == 32, "the baseline node is 32 bytes");

}  // namespace wavetrace
