// 2x2 ray packets through the top BVH and the strips (§5.3): a top node or a strip's
// kd-node is entered when any ray of the packet needs it, and its box or planes are tested
// for the four rays at once (4-lane vectors), so fetch, decode and test are shared; each
// ray keeps its own [dmin, dmax] and nearest hit. Where fewer than `min_active` rays are
// left in a strip's subtree — the incoherent case at the bottom of a detailed mesh — the
// packet falls back to single-ray traversal of that subtree, whose edge tests are SIMD
// across edges instead of across rays (the paper's switch). Runs of triangles are always
// tested ray by ray, across edges.
#pragma once

#include <bit>
#include <cstdint>
#include <optional>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/raystrips/strip_traversal.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

inline constexpr std::uint32_t kPacketRays = 4;

struct PacketTraversal {
  using Lanes = float __attribute__((vector_size(16)));
  using LaneMask = std::int32_t __attribute__((vector_size(16)));

  const BvhNode* nodes;
  const std::byte* strips;
  const glm::vec3* positions;
  std::uint32_t run_triangles;
  std::uint32_t min_active;

  // Closest hits of rays [range.begin, range.end), at most 4; `write(ray, i)` stores each answer.
  template <typename WriteHit>
  void trace(const RayBatch& rays, HitBatch& hits, RayRange range, WriteHit&& write) const {
    std::optional<StripRay> packet[kPacketRays];
    Packet lanes{};
    std::uint32_t alive = 0;
    for (std::uint32_t r = 0; r < range.size(); ++r) {
      const std::uint32_t i = range.begin + r;
      if (!(rays.flags[i] & ray_flags::alive)) continue;
      const StripRay& ray = packet[r].emplace(load_ray(rays, i));
      for (int axis = 0; axis < 3; ++axis) {
        lanes.origin[axis][r] = ray.box.origin[axis];
        lanes.inverse[axis][r] = ray.box.inverse_direction[axis];
      }
      lanes.tmin[r] = ray.tmin;
      lanes.tmax[r] = pruning_distance(ray.tmax);
      alive |= 1u << r;
    }
    struct Pending {
      std::uint32_t node, mask;
    };
    Pending stack[kMaxTreeDepth];
    std::uint32_t top = 0;
    std::uint32_t node = 0, mask = alive;
    while (mask != 0) {
      const BvhNode& current = nodes[node];
      Lanes near, far;
      const std::uint32_t inside = mask & clip_to_box(lanes, current.lower, current.upper, near, far);
      if (inside != 0) {
        if (!current.leaf()) {
          // Near child first, as the first ray of the packet sees it (by the children's centres).
          const int lead = std::countr_zero(inside);
          const BvhNode& left = nodes[current.left()];
          const BvhNode& right = nodes[current.right()];
          float left_along = 0.0f, right_along = 0.0f;
          for (int axis = 0; axis < 3; ++axis) {
            const float direction = 1.0f / lanes.inverse[axis][lead];
            left_along += (left.lower[axis] + left.upper[axis]) * direction;
            right_along += (right.lower[axis] + right.upper[axis]) * direction;
          }
          const bool left_first = !(right_along < left_along);
          stack[top++] = {left_first ? current.right() : current.left(), inside};
          node = left_first ? current.left() : current.right();
          mask = inside;
          continue;
        }
        const std::byte* strip_data = strips + std::size_t(current.first) * 4;
        for (std::uint32_t s = 0; s < current.triangle_count(); ++s) {
          const ray_strip::StripView strip(strip_data);
          traverse_strip(strip, Bounds3{current.lower, current.upper}, packet, lanes, inside, near, far);
          strip_data += strip.size();
        }
      }
      if (top == 0) break;
      --top;
      node = stack[top].node;
      mask = stack[top].mask;
    }
    for (std::uint32_t r = 0; r < range.size(); ++r) {
      if (packet[r]) {
        write(*packet[r], range.begin + r);
      } else {
        hits.set_miss(range.begin + r);
      }
    }
  }

 private:
  // The packet's rays, one lane each (dead lanes: zeros, never in a mask).
  struct Packet {
    Lanes origin[3], inverse[3];
    Lanes tmin, tmax;  // tmax: pruning_distance of each ray's nearest hit (nodes beyond it are pruned)
  };

  static std::uint32_t bits_of(LaneMask mask) {
    std::uint32_t bits = 0;
    for (std::uint32_t r = 0; r < kPacketRays; ++r) bits |= std::uint32_t(mask[r] != 0) << r;
    return bits;
  }

  // clip_to_box (kernels/ray_box.hpp) for four rays: same arithmetic, same NaN rules.
  static std::uint32_t clip_to_box(const Packet& packet, const glm::vec3& lower, const glm::vec3& upper, Lanes& near,
                                   Lanes& far) {
    near = packet.tmin;
    far = packet.tmax;
    for (int axis = 0; axis < 3; ++axis) {
      const Lanes t0 = (lower[axis] - packet.origin[axis]) * packet.inverse[axis];
      const Lanes t1 = (upper[axis] - packet.origin[axis]) * packet.inverse[axis];
      const LaneMask swap = t0 > t1;
      const Lanes entry = swap ? t1 : t0;
      const Lanes exit = (swap ? t0 : t1) * kSlabFarScale;
      near = entry > near ? entry : near;
      far = exit < far ? exit : far;
    }
    return bits_of(near <= far);
  }

  static Lanes widen_exit(Lanes t) { return t * (t > 0.0f ? Lanes{} + (1.0f + kPlaneDistanceSlack) : Lanes{} + (1.0f - kPlaneDistanceSlack)); }
  static Lanes widen_entry(Lanes t) { return t * (t > 0.0f ? Lanes{} + (1.0f - kPlaneDistanceSlack) : Lanes{} + (1.0f + kPlaneDistanceSlack)); }

  // The packet's rays in `mask` through one strip, each within its own [dmin, dmax].
  void traverse_strip(const ray_strip::StripView& strip, const Bounds3& frame, std::optional<StripRay>* packet,
                      Packet& lanes,
                      std::uint32_t mask, Lanes entry, Lanes exit) const {
    using namespace ray_strip;
    NullProbe probe;
    struct Pending {
      std::uint32_t node, first, leaves, mask;
      Lanes dmin, dmax;
    };
    Pending stack[18];
    std::uint32_t top = 0;
    const std::uint32_t triangles = strip.triangles();
    Pending current{0, 0, leaf_count(triangles), mask, entry, exit};
    while (true) {
      if (static_cast<std::uint32_t>(std::popcount(current.mask)) < min_active) {
        // Too few rays left here for the packet to pay: each goes on alone.
        for (std::uint32_t bits = current.mask; bits != 0; bits &= bits - 1) {
          const int r = std::countr_zero(bits);
          StripRay& ray = *packet[r];
          ray.traverse_subtree<false>(strip, frame, positions, current.node, current.first, current.leaves, current.dmin[r],
                                      current.dmax[r], run_triangles, probe);
          lanes.tmax[r] = pruning_distance(ray.tmax);
        }
      } else if (descends(triangles, current.first, current.leaves, run_triangles)) {
        const std::uint8_t bits = strip.node_bits(current.node);
        const int axis = bits & kAxisMask;
        const SplitPlanes planes = decode_split(strip.split_steps(current.node), frame, axis);
        const float split[2] = {planes.lower_child_max, planes.upper_child_min};
        const bool reverse = (bits & kReverse) != 0;
        const std::uint32_t first_leaves = (current.leaves + 1) / 2;
        const Lanes dmin = current.dmin;
        const Lanes dmax = current.dmax < lanes.tmax ? current.dmax : lanes.tmax;
        const Lanes inverse = lanes.inverse[axis];
        const Lanes lower_plane = (split[0] - lanes.origin[axis]) * inverse;
        const Lanes upper_plane = (split[1] - lanes.origin[axis]) * inverse;
        // Along a ray with a positive direction the lower child comes first: it ends at its
        // plane and the upper child starts at its own; a negative direction swaps the roles.
        const LaneMask positive = !(inverse < 0.0f);
        const Lanes lower_exit = widen_exit(lower_plane), lower_entry = widen_entry(lower_plane);
        const Lanes upper_exit = widen_exit(upper_plane), upper_entry = widen_entry(upper_plane);
        const Lanes lower_min = positive ? dmin : (lower_entry > dmin ? lower_entry : dmin);
        const Lanes lower_max = positive ? (lower_exit < dmax ? lower_exit : dmax) : dmax;
        const Lanes upper_min = positive ? (upper_entry > dmin ? upper_entry : dmin) : dmin;
        const Lanes upper_max = positive ? dmax : (upper_exit < dmax ? upper_exit : dmax);
        const std::uint32_t lower_mask = current.mask & bits_of(lower_min <= lower_max);
        const std::uint32_t upper_mask = current.mask & bits_of(upper_min <= upper_max);
        const Pending strip_first{current.node + 1, current.first, first_leaves, 0, {}, {}};
        const Pending strip_second{current.node + first_leaves, current.first + first_leaves,
                                   current.leaves - first_leaves, 0, {}, {}};
        Pending lower = reverse ? strip_second : strip_first;
        Pending upper = reverse ? strip_first : strip_second;
        lower.mask = lower_mask, lower.dmin = lower_min, lower.dmax = lower_max;
        upper.mask = upper_mask, upper.dmin = upper_min, upper.dmax = upper_max;
        const bool lower_first = positive[std::countr_zero(current.mask)] != 0;
        Pending& near = lower_first ? lower : upper;
        Pending& far = lower_first ? upper : lower;
        if (near.mask != 0) {
          if (far.mask != 0) stack[top++] = far;
          current = near;
          continue;
        }
        if (far.mask != 0) {
          current = far;
          continue;
        }
      } else {
        const std::uint32_t begin = 2 * current.first;
        const std::uint32_t end = std::min(2 * (current.first + current.leaves), triangles);
        for (std::uint32_t ray_bits = current.mask; ray_bits != 0; ray_bits &= ray_bits - 1) {
          const int r = std::countr_zero(ray_bits);
          packet[r]->test_run<false>(strip, positions, begin, end, probe);
          lanes.tmax[r] = pruning_distance(packet[r]->tmax);
        }
      }
      // Pop the next subtree that some ray can still improve on.
      while (true) {
        if (top == 0) return;
        current = stack[--top];
        current.mask &= bits_of(current.dmin <= lanes.tmax);
        if (current.mask != 0) break;
      }
    }
  }
};

}  // namespace wavetrace
