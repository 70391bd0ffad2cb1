// The surface-area cut of a binary SAH tree into 8-wide nodes (collapse_plan.hpp).
#include "wavetrace/accel/bvh/collapse_plan.hpp"

#include <algorithm>
#include <limits>

namespace wavetrace {
namespace {

float half_area(const Bounds3& b) {
  const glm::vec3 e = b.extent();
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

}  // namespace

CollapsePlan::CollapsePlan(const BuildTree& tree)
    : best_(tree.nodes.size() * kWidth), split_(tree.nodes.size() * kWidth), opened_split_(tree.nodes.size()) {
  const float root_area = std::max(half_area(tree.nodes[0].bounds), std::numeric_limits<float>::min());
  // Children before parents: an explicit post-order, the tree may be deeper than the call stack likes.
  std::vector<std::uint32_t> order, pending = {0};
  order.reserve(tree.nodes.size());
  while (!pending.empty()) {
    const std::uint32_t n = pending.back();
    pending.pop_back();
    order.push_back(n);
    if (!tree.nodes[n].leaf()) pending.insert(pending.end(), {tree.nodes[n].left, tree.nodes[n].right});
  }
  for (auto n = order.rbegin(); n != order.rend(); ++n) {
    const BuildNode& node = tree.nodes[*n];
    float* best = &best_[std::size_t(*n) * kWidth];
    std::uint8_t* split = &split_[std::size_t(*n) * kWidth];
    if (node.leaf()) {  // a leaf is one child wherever it goes; its own cost is the same in every cut
      std::fill(best, best + kWidth, 0.0f);
      std::fill(split, split + kWidth, std::uint8_t{0});
      continue;
    }
    const float* left = &best_[std::size_t(node.left) * kWidth];
    const float* right = &best_[std::size_t(node.right) * kWidth];
    // best[k - 1]: the cheapest way to hang the subtree below a node as at most k children.
    auto cheapest_split = [&](int k, std::uint8_t& chosen) {
      float cost = std::numeric_limits<float>::infinity();
      for (int j = 1; j < k; ++j) {
        const float c = left[j - 1] + right[k - j - 1];
        if (c < cost) cost = c, chosen = static_cast<std::uint8_t>(j);
      }
      return cost;
    };
    std::uint8_t opened = 1;
    const float as_node = half_area(node.bounds) / root_area + cheapest_split(kWidth, opened);
    opened_split_[*n] = opened;
    best[0] = as_node;
    split[0] = 0;
    for (int k = 2; k <= kWidth; ++k) {
      std::uint8_t chosen = 0;
      const float spread = cheapest_split(k, chosen);
      best[k - 1] = spread < as_node ? spread : as_node;
      split[k - 1] = spread < as_node ? chosen : 0;
    }
  }
}

std::vector<std::uint32_t> CollapsePlan::children(const BuildTree& tree, std::uint32_t root) const {
  if (tree.nodes[root].leaf()) return {root};
  std::vector<std::uint32_t> out;
  const int left = opened_split_[root];
  frontier(tree, tree.nodes[root].left, left, out);
  frontier(tree, tree.nodes[root].right, kWidth - left, out);
  return out;
}

void CollapsePlan::frontier(const BuildTree& tree, std::uint32_t n, int k, std::vector<std::uint32_t>& out) const {
  const std::uint8_t j = split_[std::size_t(n) * kWidth + k - 1];
  if (j == 0) return out.push_back(n);
  frontier(tree, tree.nodes[n].left, j, out);
  frontier(tree, tree.nodes[n].right, k - j, out);
}

}  // namespace wavetrace
