// One ray through a tree of 32-byte BvhNodes, near child first with a short stack of
// (node, entry distance): the `bvh` baseline's traversal, and the top level that Ray-Strips
// and HMQ put above their compact leaves.
#pragma once

#include <cstdint>
#include <limits>
#include <utility>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {

// `visit_leaf(node)` handles a leaf and returns true to end the walk (an any-hit query
// found one); it may shrink `tmax`, which prunes what is left on the stack (beyond
// pruning_distance(tmax), so that a tied triangle is never pruned). Always inlined:
// as a call, the leaf visit cannot be folded into the loop (7% slower on the bvh baseline).
template <typename Probe, typename VisitLeaf>
[[gnu::always_inline]] inline void walk_bvh(const BvhNode* nodes, const BoxRay& ray, float tmin, const float& tmax, Probe& probe,
              VisitLeaf&& visit_leaf) {
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  struct StackEntry {
    std::uint32_t node;
    float distance;
  };
  StackEntry stack[kMaxTreeDepth];
  std::uint32_t top = 0, node = 0;
  probe.read(nodes, sizeof(BvhNode));
  if (intersect_box(ray, nodes[0].lower, nodes[0].upper, tmin, tmax) == kInfinity) return;
  while (true) {
    const BvhNode& current = nodes[node];
    if (current.leaf()) {
      if (visit_leaf(current)) return;
    } else {
      std::uint32_t near = current.left(), far = current.right();
      probe.read(nodes + near, sizeof(BvhNode));
      probe.read(nodes + far, sizeof(BvhNode));
      const float limit = pruning_distance(tmax);
      float near_distance = intersect_box(ray, nodes[near].lower, nodes[near].upper, tmin, limit);
      float far_distance = intersect_box(ray, nodes[far].lower, nodes[far].upper, tmin, limit);
      if (far_distance < near_distance) {
        std::swap(near, far);
        std::swap(near_distance, far_distance);
      }
      if (near_distance != kInfinity) {
        if (far_distance != kInfinity) stack[top++] = {far, far_distance};
        node = near;
        continue;
      }
    }
    while (top > 0 && stack[top - 1].distance > pruning_distance(tmax)) --top;
    if (top == 0) return;
    node = stack[--top].node;
  }
}

}  // namespace wavetrace
