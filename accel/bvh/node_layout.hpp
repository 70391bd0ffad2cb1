// Node orders in memory for a built tree: depth-first (a node, then its left subtree,
// then its right), breadth-first (level by level), and van Emde Boas (cache-oblivious:
// the top half of the levels, recursively, then each bottom subtree, recursively).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "accel/bvh/sah_builder.hpp"

namespace wavetrace {

enum class NodeLayout { depth_first, breadth_first, van_emde_boas };

NodeLayout parse_node_layout(const std::string& text);  // "depth_first" | "breadth_first" | "veb"
std::string to_string(NodeLayout layout);

// Build-node ids in the order they are to be stored.
std::vector<std::uint32_t> node_order(const BuildTree& tree, NodeLayout layout);

}  // namespace wavetrace
