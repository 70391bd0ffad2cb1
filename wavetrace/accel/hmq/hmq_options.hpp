// The options of `hmq` (either width), apart from its builders so that they and the front
// door (hmq_accelerator.hpp) include them without including each other.
#pragma once

#include <cstdint>
#include <optional>

#include "wavetrace/accel/bvh/node_layout.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct HmqOptions {
  // Grid bits per axis (1 .. 24); the paper uses 16. Ignored when epsilon is set.
  std::uint32_t bits = 16;
  // Error bound in scene units (0: unset): the grid is the coarsest on which no vertex moves
  // more than this. Setting it together with bits other than 16 is an error.
  double epsilon = 0.0;
  // Most triangles per leaf, 1 .. 14 (the paper's table: 4, 8, 12); 0: the width's own
  // (leaf_triangles).
  std::uint32_t leaf_size = 0;
  double top_fraction = 0.05;    // share of the BVH's nodes kept uncompressed at its top, 0 .. 1
                                 // (binary layout only: the 8-wide one quantizes every node)
  // 2: the paper's binary tree of 4-byte nodes in blocks; 8: 64-byte nodes of eight children
  // quantized to 8 bits per plane, tested in AVX2 lanes (accel/bvh/quantized_wide_node.hpp). Same leaves.
  std::uint32_t width = 2;
  // The 8-wide nodes' order in the array and so in a world file (width 8 only; the binary
  // layout keeps its blocks). van Emde Boas by default: a paged render of room:8M at a 24%
  // budget read 5-9% fewer pages than depth first (10%: 10-14%), at the same bytes and the
  // same in-core speed (docs/measurements.md).
  NodeLayout layout = NodeLayout::van_emde_boas;
  // Width 8: each group of sibling nodes followed by its nodes' leaf records in one array
  // (interleave_leaf_records), so a paged walk reads a leaf from its parent's page. With van
  // Emde Boas nodes, 11-27% fewer pages read than depth first apart, for 3% more bytes (the
  // alignment of each group of nodes): off by default, on for worlds paged from disk.
  bool leaves_beside_nodes = false;
  std::uint32_t bins = 16;       // SAH bins
  // The box the global grid spans: the whole scene's when a chunk is built, so that every
  // chunk snaps to the same grid and shared vertices decode alike; unset: the mesh's box.
  std::optional<Bounds3> grid_bounds;
  bool operator==(const HmqOptions&) const = default;

  // The leaf size built: the one asked for, else the paper's 8 for the binary layout and 14,
  // the records' most, for width 8, whose leaves of 14 take about a sixth fewer bytes than of 8
  // at the same speed (room:1M 9.4 -> 7.9 B/tri; docs/measurements.md, "Leaves of fourteen").
  std::uint32_t leaf_triangles() const { return leaf_size != 0 ? leaf_size : width == 8 ? 14 : 8; }
};

}  // namespace wavetrace
