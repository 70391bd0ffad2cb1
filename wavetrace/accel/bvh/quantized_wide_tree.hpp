// Building a tree of quantized wide nodes (quantized_wide_node.hpp) from a binary SAH tree:
// which binary nodes become wide nodes, the quantized child boxes, and the leaf records laid
// out by the owner through a callback.
#pragma once

#include <cstdint>
#include <functional>
#include <span>

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

// One array holding the nodes and the owner's leaf records side by side, in 64-byte units:
// each group of sibling nodes (in the nodes' order, 64-byte aligned) is followed by the leaf
// records of its nodes, so a leaf lies beside the node that names it and a paged walk's last
// steps read one page, not a node page and a leaf page. child_base counts 64-byte units of
// the array, leaf_base `unit_bytes` units from its start (records are multiples of
// unit_bytes; `records` are the encoder's, a node's leaves consecutive from leaf_base).
// `slack_bytes` zero bytes follow the last record (read slack); the array is zero-padded to
// whole units. Throws std::length_error when a leaf reference would pass 2^31 units.
struct InterleavedWideTree {
  LargeArray<QuantizedWideNode> units;
  std::size_t padding_bytes = 0;  // the zeros that align each group of nodes and the end
};
InterleavedWideTree interleave_leaf_records(std::span<const QuantizedWideNode> nodes, std::span<const std::byte> records,
                                            std::size_t unit_bytes, std::size_t slack_bytes);

}  // namespace wavetrace
