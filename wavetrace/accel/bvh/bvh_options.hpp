// The options of `bvh` (either width), apart from its builders so that they and the
// front door (bvh_accelerator.hpp) include them without including each other.
#pragma once

#include <cstdint>

#include "wavetrace/accel/bvh/indexed_face_set.hpp"
#include "wavetrace/accel/bvh/node_layout.hpp"

namespace wavetrace {

struct BvhOptions {
  // 1..16; 0: the width's own (leaf_triangles).
  std::uint32_t max_leaf_size = 0;
  NodeLayout layout = NodeLayout::depth_first;
  // input: leaves index the mesh's own triangles; morton: the BVH keeps a copy of the
  // indexed face set with triangles sorted along a Morton curve and vertices renumbered in
  // first-use order, so a leaf's triangles and vertices sit close together in memory.
  TriangleOrder triangle_order = TriangleOrder::input;
  std::uint32_t bins = 16;
  // 2: the papers' baseline of 32-byte binary nodes. 8: the same tree collapsed into
  // 256-byte 8-wide nodes tested with AVX2 (wide_bvh_node.hpp); node layout is then depth-first.
  std::uint32_t width = 2;
  // The binary tree keeps the papers' leaves of at most four; the 8-wide tree's leaves are
  // blocks of four, and the SAH counting blocks makes them up to four blocks where that pays:
  // on this project's Zen 5 machine 5-10% faster on camera and diffuse rays than at most one
  // block, in 7% fewer bytes (docs/measurements.md, "bvh:width=8's leaves of up to sixteen").
  std::uint32_t leaf_triangles() const { return max_leaf_size != 0 ? max_leaf_size : width == 8 ? 16 : 4; }
  bool operator==(const BvhOptions&) const = default;
};

}  // namespace wavetrace
