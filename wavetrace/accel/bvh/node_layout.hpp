// Node orders in memory for a built tree: depth-first (a node, then its left subtree,
// then its right), breadth-first (level by level), and van Emde Boas (cache-oblivious:
// the top half of the levels, recursively, then each bottom subtree, recursively).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {

enum class NodeLayout { depth_first, breadth_first, van_emde_boas };

NodeLayout parse_node_layout(const std::string& text);  // "depth_first" | "breadth_first" | "veb"
std::string to_string(NodeLayout layout);

// Build-node ids in the order they are to be stored.
std::vector<std::uint32_t> node_order(const BuildTree& tree, NodeLayout layout);

// The tree as 32-byte nodes in `order` (array node i is build node order[i]); a leaf's `first`
// is what `leaf_first(build_node)` returns, called for the leaves in array order.
template <typename LeafFirst>
void flatten_tree(const BuildTree& tree, const std::vector<std::uint32_t>& order, LargeArray<BvhNode>& nodes,
                  LeafFirst&& leaf_first) {
  std::vector<std::uint32_t> position_of(tree.nodes.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) position_of[order[i]] = i;
  nodes.resize(order.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) {
    const BuildNode& built = tree.nodes[order[i]];
    BvhNode& node = nodes[i];
    node.lower = built.bounds.lower;
    node.upper = built.bounds.upper;
    if (built.leaf()) {
      node.first = leaf_first(built);
      node.count = BvhNode::kLeafFlag | built.count;
    } else {
      node.first = position_of[built.left];
      node.count = position_of[built.right];
    }
  }
}

}  // namespace wavetrace
