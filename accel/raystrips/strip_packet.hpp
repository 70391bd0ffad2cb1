// 2x2 ray packets through the top BVH and the strips (§5.3): a node or a strip's kd-node
// is entered when any ray of the packet needs it, so its fetch and decode are shared; each
// ray keeps its own [dmin, dmax] and nearest hit. Where fewer than `min_active` rays are
// left in a strip's subtree — the incoherent case at the bottom of a detailed mesh — the
// packet falls back to single-ray traversal of that subtree, whose edge tests are SIMD
// across edges instead of across rays (the paper's switch).
#pragma once

#include <bit>
#include <cstdint>
#include <optional>

#include "accel/bvh/bvh_node.hpp"
#include "accel/bvh/sah_builder.hpp"
#include "accel/raystrips/strip_traversal.hpp"
#include "memory/ray_batch.hpp"

namespace wavetrace {

inline constexpr std::uint32_t kPacketRays = 4;

struct PacketTraversal {
  const BvhNode* nodes;
  const std::byte* strips;
  const glm::vec3* positions;
  std::uint32_t run_triangles;
  std::uint32_t min_active;

  // Closest hits of rays [range.begin, range.end), at most 4; `write(ray, i)` stores each answer.
  template <typename WriteHit>
  void trace(const RayBatch& rays, HitBatch& hits, RayRange range, WriteHit&& write) const {
    std::optional<StripRay> packet[kPacketRays];
    std::uint32_t alive = 0;
    for (std::uint32_t r = 0; r < range.size(); ++r) {
      const std::uint32_t i = range.begin + r;
      if (!(rays.flags[i] & ray_flags::alive)) continue;
      packet[r].emplace(glm::vec3(rays.origin_x[i], rays.origin_y[i], rays.origin_z[i]),
                        glm::vec3(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]), rays.tmin[i],
                        rays.tmax[i]);
      alive |= 1u << r;
    }
    struct Pending {
      std::uint32_t node, mask;
    };
    Pending stack[kMaxTreeDepth];
    std::uint32_t top = 0;
    std::uint32_t node = 0, mask = alive;
    while (mask != 0) {
      // The node's box, for the rays still with it; leaves keep each ray's [near, far].
      const BvhNode& current = nodes[node];
      float near[kPacketRays], far[kPacketRays];
      std::uint32_t inside = 0;
      for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1) {
        const int r = std::countr_zero(bits);
        const StripRay& ray = *packet[r];
        if (clip_to_box(ray.box, current.lower, current.upper, ray.tmin, ray.tmax, near[r], far[r])) inside |= 1u << r;
      }
      if (inside != 0) {
        if (current.leaf()) {
          const std::byte* strip_data = strips + std::size_t(current.first) * 4;
          for (std::uint32_t s = 0; s < current.triangle_count(); ++s) {
            const ray_strip::StripView strip(strip_data);
            traverse_strip(strip, packet, inside, near, far);
            strip_data += strip.size();
          }
        } else {
          // Near child first, as the first ray of the packet sees it.
          const StripRay& lead = *packet[std::countr_zero(inside)];
          const BvhNode& left = nodes[current.left()];
          const BvhNode& right = nodes[current.right()];
          const float left_distance = intersect_box(lead.box, left.lower, left.upper, lead.tmin, lead.tmax);
          const float right_distance = intersect_box(lead.box, right.lower, right.upper, lead.tmin, lead.tmax);
          const bool left_first = left_distance <= right_distance;
          stack[top++] = {left_first ? current.right() : current.left(), inside};
          node = left_first ? current.left() : current.right();
          mask = inside;
          continue;
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
        write_miss(hits, range.begin + r);
      }
    }
  }

 private:
  static void write_miss(HitBatch& hits, std::uint32_t i) { hits.set_miss(i); }

  // The packet's rays in `mask` through one strip, each within its own [dmin, dmax].
  void traverse_strip(const ray_strip::StripView& strip, std::optional<StripRay>* packet, std::uint32_t mask,
                      const float* entry, const float* exit) const {
    using namespace ray_strip;
    NullProbe probe;
    struct Pending {
      std::uint32_t node, first, leaves, mask;
      float dmin[kPacketRays], dmax[kPacketRays];
    };
    Pending stack[18];
    std::uint32_t top = 0;
    const std::uint32_t triangles = strip.triangles();
    Pending current{0, 0, leaf_count(triangles), mask, {}, {}};
    for (std::uint32_t r = 0; r < kPacketRays; ++r) {
      current.dmin[r] = entry[r];
      current.dmax[r] = exit[r];
    }
    while (true) {
      if (static_cast<std::uint32_t>(std::popcount(current.mask)) < min_active) {
        // Too few rays left here for the packet to pay: each goes on alone.
        for (std::uint32_t bits = current.mask; bits != 0; bits &= bits - 1) {
          const int r = std::countr_zero(bits);
          StripRay& ray = *packet[r];
          ray.traverse_subtree<false>(strip, positions, current.node, current.first, current.leaves, current.dmin[r],
                                      current.dmax[r], run_triangles, probe);
        }
      } else if (current.leaves >= 2 &&
                 std::min(2 * (current.first + current.leaves), triangles) - 2 * current.first > run_triangles) {
        const float* split = strip.splits(current.node);
        const std::uint8_t bits = strip.node_bits(current.node);
        const int axis = bits & kAxisMask;
        const bool reverse = (bits & kReverse) != 0;
        const std::uint32_t first_leaves = (current.leaves + 1) / 2;
        Pending strip_first{current.node + 1, current.first, first_leaves, 0, {}, {}};
        Pending strip_second{current.node + first_leaves, current.first + first_leaves, current.leaves - first_leaves,
                             0, {}, {}};
        Pending& lower = reverse ? strip_second : strip_first;
        Pending& upper = reverse ? strip_first : strip_second;
        for (std::uint32_t ray_bits = current.mask; ray_bits != 0; ray_bits &= ray_bits - 1) {
          const int r = std::countr_zero(ray_bits);
          const StripRay& ray = *packet[r];
          const float inverse = ray.box.inverse_direction[axis];
          const float dmin = current.dmin[r], dmax = std::min(current.dmax[r], ray.tmax);
          const float lower_plane = (split[0] - ray.box.origin[axis]) * inverse;
          const float upper_plane = (split[1] - ray.box.origin[axis]) * inverse;
          float lower_min = dmin, lower_max = dmax, upper_min = dmin, upper_max = dmax;
          if (!std::signbit(inverse)) {  // the lower child comes first along the ray
            const float exit_plane = widen_exit(lower_plane), entry_plane = widen_entry(upper_plane);
            lower_max = exit_plane < lower_max ? exit_plane : lower_max;
            upper_min = entry_plane > upper_min ? entry_plane : upper_min;
          } else {
            const float exit_plane = widen_exit(upper_plane), entry_plane = widen_entry(lower_plane);
            upper_max = exit_plane < upper_max ? exit_plane : upper_max;
            lower_min = entry_plane > lower_min ? entry_plane : lower_min;
          }
          lower.dmin[r] = lower_min, lower.dmax[r] = lower_max;
          upper.dmin[r] = upper_min, upper.dmax[r] = upper_max;
          lower.mask |= std::uint32_t(lower_min <= lower_max) << r;
          upper.mask |= std::uint32_t(upper_min <= upper_max) << r;
        }
        const StripRay& lead = *packet[std::countr_zero(current.mask)];
        const bool lower_first = !std::signbit(lead.box.inverse_direction[axis]);
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
          packet[std::countr_zero(ray_bits)]->test_run<false>(strip, positions, begin, end, probe);
        }
      }
      // Pop the next subtree that some ray can still improve on.
      while (true) {
        if (top == 0) return;
        current = stack[--top];
        std::uint32_t still = 0;
        for (std::uint32_t bits = current.mask; bits != 0; bits &= bits - 1) {
          const int r = std::countr_zero(bits);
          still |= std::uint32_t(current.dmin[r] <= packet[r]->tmax) << r;
        }
        current.mask = still;
        if (still != 0) break;
      }
    }
  }
};

}  // namespace wavetrace
