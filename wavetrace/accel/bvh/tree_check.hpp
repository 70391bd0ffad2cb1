// Checks of a loaded tree before any ray walks it: a world file that passed its checksums may
// still have been written by something other than wavetrace (the world-file fuzz target
// writes such files), and a child index past the array, a cycle, or a tree deeper than the
// walk's stack would otherwise be a crash or a hang, not an error naming the file.
//
// The shared rule: a child lies after its parent in the array (all three node layouts put
// parents first, and the wide and quantized layouts inherit their order), so every walk ends;
// depth is counted from the root and must stay under kMaxTreeDepth, which sizes every stack.
//
// Checked so: bvh (binary and 8-wide), the chunked top, hmq's float top and quantized 8-wide
// tree with their leaf records (hmq/block_check.hpp), raystrips' tops (binary and quantized)
// with their strips (raystrips/strip_check.hpp).
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/quantized_wide_node.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/bvh/wide_bvh_node.hpp"
#include "wavetrace/accel/section_archive.hpp"

namespace wavetrace {

// Depths of a tree's nodes, filled parent first; `link` fails unless the child follows it.
class TreeDepths {
 public:
  TreeDepths(std::size_t nodes, const SectionLoader& in, std::string_view section)
      : depth_(nodes, 0), in_(in), section_(section) {
    if (nodes == 0) in.fail(section, "is empty");
  }
  void link(std::size_t parent, std::uint64_t child) {
    if (child <= parent || child >= depth_.size()) {
      in_.fail(section_, fmt::format("node {} names child {}, which does not lie after it among the {} nodes", parent,
                                     child, depth_.size()));
    }
    const std::uint32_t depth = depth_[parent] + 1u;
    if (depth >= kMaxTreeDepth) in_.fail(section_, fmt::format("is deeper than {} levels", kMaxTreeDepth));
    depth_[child] = std::max<std::uint8_t>(depth_[child], static_cast<std::uint8_t>(depth));
  }

 private:
  std::vector<std::uint8_t> depth_;
  const SectionLoader& in_;
  std::string_view section_;
};

// A binary tree of BvhNodes; `check_leaf(node)` fails for a leaf naming what does not exist.
template <typename CheckLeaf>
void check_tree(std::span<const BvhNode> nodes, const SectionLoader& in, std::string_view section, CheckLeaf&& check_leaf) {
  TreeDepths depths(nodes.size(), in, section);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (nodes[i].leaf()) {
      check_leaf(nodes[i]);
    } else {
      depths.link(i, nodes[i].left());
      depths.link(i, nodes[i].right());
    }
  }
}

// An 8-wide tree; `check_leaf(first, count)` fails for a leaf lane naming what does not
// exist. A lane whose six bounds are +inf is never entered (wide_bvh_node.hpp) and not read.
template <typename CheckLeaf>
void check_tree(std::span<const WideBvhNode> nodes, const SectionLoader& in, std::string_view section,
                CheckLeaf&& check_leaf) {
  TreeDepths depths(nodes.size(), in, section);
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const WideBvhNode& node = nodes[i];
    for (int k = 0; k < WideBvhNode::kWidth; ++k) {
      const bool unused = node.lower_x[k] == kInfinity && node.upper_x[k] == kInfinity && node.lower_y[k] == kInfinity &&
                          node.upper_y[k] == kInfinity && node.lower_z[k] == kInfinity && node.upper_z[k] == kInfinity;
      if (unused) continue;
      if (node.count[k] == 0) depths.link(i, node.child[k]);
      else check_leaf(node.child[k], node.count[k]);
    }
  }
}

// The used slots of a quantized 8-wide node, `name` `index` in errors: inner children by their
// place (child_base counts them), leaf children by reference and weight. Empty slots (meta 0)
// are never entered.
template <typename OnInner, typename OnLeaf>
void for_each_used_slot(const QuantizedWideNode& node, std::uint64_t index, std::string_view name,
                        const SectionLoader& in, std::string_view section, OnInner&& on_inner, OnLeaf&& on_leaf) {
  std::uint64_t inner = 0, weight = 0;
  for (int k = 0; k < QuantizedWideNode::kWidth; ++k) {
    const std::uint8_t meta = node.meta[k];
    if (meta == 0) continue;
    if (meta == QuantizedWideNode::kInnerMeta) {
      on_inner(std::uint64_t(node.child_base) + inner++);
    } else {
      const std::uint64_t reference = node.leaf_base + weight;
      // The walk marks leaf references with bit 31 (kWideLeafReference).
      if (reference >= (std::uint64_t{1} << 31)) {
        in.fail(section, fmt::format("{} {} has a leaf reference past 2^31", name, index));
      }
      on_leaf(static_cast<std::uint32_t>(reference), meta);
      weight += meta;
    }
  }
}

// A quantized 8-wide tree (quantized_wide_node.hpp); `check_leaf(reference, weight)` fails
// for a leaf child naming what does not exist.
template <typename CheckLeaf>
void check_tree(std::span<const QuantizedWideNode> nodes, const SectionLoader& in, std::string_view section,
                CheckLeaf&& check_leaf) {
  TreeDepths depths(nodes.size(), in, section);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    for_each_used_slot(nodes[i], i, "node", in, section, [&](std::uint64_t child) { depths.link(i, child); },
                       check_leaf);
  }
}

// A quantized 8-wide tree whose array also holds leaf records (interleave_leaf_records in
// quantized_wide_tree.hpp): only what the root reaches is a node, so the check walks from the
// root, each node reached once and after its parent. Returns the number of nodes.
template <typename CheckLeaf>
std::size_t check_tree_from_root(std::span<const QuantizedWideNode> units, const SectionLoader& in,
                                 std::string_view section, CheckLeaf&& check_leaf) {
  if (units.empty()) in.fail(section, "is empty");
  std::vector<bool> reached(units.size(), false);
  std::vector<std::pair<std::uint64_t, std::uint32_t>> pending = {{0, 0}};  // unit, depth
  reached[0] = true;
  std::size_t nodes = 0;
  while (!pending.empty()) {
    // Named copies, not a structured binding: the lambda below captures them (clang 14 cannot).
    const std::uint64_t i = pending.back().first;
    const std::uint32_t depth = pending.back().second;
    pending.pop_back();
    ++nodes;
    for_each_used_slot(
        units[i], i, "node at unit", in, section,
        [&](std::uint64_t child) {
          if (child <= i || child >= units.size() || reached[child]) {
            in.fail(section, fmt::format("node at unit {} names child {}, which does not lie after it among the {} "
                                         "units or is named twice",
                                         i, child, units.size()));
          }
          if (depth + 1 >= kMaxTreeDepth) in.fail(section, fmt::format("is deeper than {} levels", kMaxTreeDepth));
          reached[child] = true;
          pending.emplace_back(child, depth + 1);
        },
        check_leaf);
  }
  return nodes;
}

// A leaf's triangle slots [first, first + count) within `slots`, and (checked once for the
// whole array by the caller) each slot naming a triangle.
inline void check_leaf_slots(std::uint64_t first, std::uint64_t count, std::size_t slots, const SectionLoader& in,
                             std::string_view section) {
  if (count == 0 || first + count > slots) {
    in.fail(section, fmt::format("has a leaf of triangle slots [{}, {}) beyond its {} slots", first, first + count, slots));
  }
}

}  // namespace wavetrace
