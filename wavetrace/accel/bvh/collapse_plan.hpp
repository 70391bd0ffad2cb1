// Which binary nodes of a SAH tree become the nodes of an 8-wide tree: the cut that minimizes
// the wide nodes' summed surface area. Shared by bvh:width=8 and the quantized wide trees.
#pragma once

#include <cstdint>
#include <vector>

#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {

// Which binary nodes become wide nodes (Ylitie et al. 2017, §3.1, without their leaf choices:
// the owners' leaves are fixed): the cut of the binary tree into nodes of at most eight
// children that minimizes the summed surface area of the wide nodes (the chance a ray visits
// each). Greedy collapsing (open the widest child until eight) left HMQ's nodes half empty
// near the leaves: 4.0 children a node on room:1M, against 6.2 with this cut. No price per
// node beyond its area: 1e-4 of the root's (8% fewer nodes) measured no faster and would tie
// the cut to the scene's size.
class CollapsePlan {
 public:
  static constexpr int kWidth = 8;

  explicit CollapsePlan(const BuildTree& tree);

  // The children of the wide node for binary node `root` (a leaf at the root: itself).
  std::vector<std::uint32_t> children(const BuildTree& tree, std::uint32_t root) const;

 private:
  // Appends the children that binary node `n` becomes when it may take `k` slots.
  void frontier(const BuildTree& tree, std::uint32_t n, int k, std::vector<std::uint32_t>& out) const;

  // Every node's entries are written by the plan before any is read (an inner node's split
  // only), so the arrays are not zeroed first: that was a pass over 41 bytes a node.
  UnfilledLargeArray<float> best_;
  UnfilledLargeArray<std::uint8_t> split_;         // 0: the node itself is the child; j: left gets j slots
  UnfilledLargeArray<std::uint8_t> opened_split_;  // a wide node's split of its eight slots, left : right
};

}  // namespace wavetrace
