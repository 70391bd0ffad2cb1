// The three node orders, iteratively where recursion depth could follow the tree's depth.
#include "wavetrace/accel/bvh/node_layout.hpp"

#include <deque>
#include <stdexcept>

namespace wavetrace {
namespace {

void depth_first(const BuildTree& tree, std::vector<std::uint32_t>& order) {
  std::vector<std::uint32_t> stack = {0};
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    order.push_back(node);
    const BuildNode& n = tree.nodes[node];
    if (!n.leaf()) {
      stack.push_back(n.right);
      stack.push_back(n.left);
    }
  }
}

void breadth_first(const BuildTree& tree, std::vector<std::uint32_t>& order) {
  std::deque<std::uint32_t> queue = {0};
  while (!queue.empty()) {
    const std::uint32_t node = queue.front();
    queue.pop_front();
    order.push_back(node);
    const BuildNode& n = tree.nodes[node];
    if (!n.leaf()) {
      queue.push_back(n.left);
      queue.push_back(n.right);
    }
  }
}

// Lays out the `levels` top levels of the subtree at `root`; the nodes just below them
// go to `frontier` for the caller to lay out next. Recursion depth is O(log levels).
void van_emde_boas(const BuildTree& tree, std::uint32_t root, std::uint32_t levels, std::vector<std::uint32_t>& order,
                   std::vector<std::uint32_t>& frontier) {
  if (levels == 1) {
    order.push_back(root);
    const BuildNode& n = tree.nodes[root];
    if (!n.leaf()) {
      frontier.push_back(n.left);
      frontier.push_back(n.right);
    }
    return;
  }
  const std::uint32_t top = levels / 2;
  std::vector<std::uint32_t> middle;
  van_emde_boas(tree, root, top, order, middle);
  for (const std::uint32_t subtree : middle) van_emde_boas(tree, subtree, levels - top, order, frontier);
}

}  // namespace

NodeLayout parse_node_layout(const std::string& text) {
  if (text == "depth_first") return NodeLayout::depth_first;
  if (text == "breadth_first") return NodeLayout::breadth_first;
  if (text == "veb") return NodeLayout::van_emde_boas;
  throw std::invalid_argument("unknown node layout '" + text + "' (depth_first, breadth_first, veb)");
}

std::string to_string(NodeLayout layout) {
  switch (layout) {
    case NodeLayout::breadth_first: return "breadth_first";
    case NodeLayout::van_emde_boas: return "veb";
    default: return "depth_first";
  }
}

std::vector<std::uint32_t> node_order(const BuildTree& tree, NodeLayout layout) {
  std::vector<std::uint32_t> order;
  order.reserve(tree.nodes.size());
  switch (layout) {
    case NodeLayout::depth_first: depth_first(tree, order); break;
    case NodeLayout::breadth_first: breadth_first(tree, order); break;
    case NodeLayout::van_emde_boas: {
      std::vector<std::uint32_t> below;
      van_emde_boas(tree, 0, tree.depth(), order, below);
      break;
    }
  }
  return order;
}

}  // namespace wavetrace
