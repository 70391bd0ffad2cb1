// Building a tree of quantized wide nodes (quantized_wide_node.hpp) from a binary SAH tree:
// which binary nodes become wide nodes, the quantized child boxes, and the leaf records laid
// out by the owner through a callback.
#pragma once

#include <cstdint>
#include <functional>

#include "wavetrace/accel/bvh/node_layout.hpp"
#include "wavetrace/accel/bvh/quantized_wide_node.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {

// Stores the binary leaf `leaf` (whose decoded box is `box`) in the owner's leaf data and
// returns its weight, 1 .. 254 (quantized_wide_node.hpp). Called once per leaf, in the
// order the references count: a node's leaves one after another, nodes depth first.
using EncodeWideLeaf = std::function<std::uint32_t(const BuildNode& leaf, const Bounds3& box)>;

struct QuantizedWideTree {
  LargeArray<QuantizedWideNode> nodes;  // node 0 is the root, framed by root_frame
  Bounds3 root_frame;
  std::size_t children = 0;  // leaves and inner nodes below the root, for the build notes
};

// Throws std::length_error when the leaf weights sum to 2^31 or more (the references' range).
// `layout` orders the nodes in the array (the leaves keep the depth-first order the encoder
// calls them in): a node's inner children stay consecutive whatever the order, so the unit
// ordered is a group of siblings (see reorder_wide_nodes).
QuantizedWideTree build_quantized_wide_tree(const BuildTree& tree, const EncodeWideLeaf& encode_leaf,
                                            NodeLayout layout = NodeLayout::depth_first);

// Reorders a tree laid out depth first (every child after its parent, as the encoder leaves
// it) into `layout`, with child_base rewritten: depth_first is the identity; breadth_first
// lays sibling groups level by level; van_emde_boas lays the top half of the group levels
// recursively, then each subtree below them recursively (cache-oblivious, as Yoon and
// Lindstrom 2006 lay out BVHs for out-of-core walks), so that a ray's path from a chunk's root
// crosses few pages of any size and a page near the root holds only nodes near the root.
void reorder_wide_nodes(LargeArray<QuantizedWideNode>& nodes, NodeLayout layout);

}  // namespace wavetrace
