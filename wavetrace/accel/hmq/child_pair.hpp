// Both children of an HMQ node decoded and tested against one ray at once, a child per half
// of an 8-lane vector (x, y, z, unused). The float operations are those of decode_child_box
// and intersect_box lane by lane, so boxes and distances are bit-identical to theirs (the
// encoder's boxes, hence the leaves' grid boxes, stay the ones the decoder sees).
#pragma once

#include <cstdint>
#include <limits>

#include "wavetrace/accel/hmq/hmq_format.hpp"
#include "wavetrace/kernels/ray_box.hpp"

namespace wavetrace::hmq {

struct ChildPair {
  Box box[2];
  float distance[2];  // entry distance, +inf on a miss
};

inline ChildPair decode_and_intersect_children(const Box& parent, std::uint32_t first, std::uint32_t second,
                                               const BoxRay& ray, float tmin, float tmax) {
  using Lanes = float __attribute__((vector_size(32)));
  using Words = std::uint32_t __attribute__((vector_size(32)));
  const glm::vec3 &lower = parent.lower, &upper = parent.upper;
  const Lanes parent_lower = {lower.x, lower.y, lower.z, 0.0f, lower.x, lower.y, lower.z, 0.0f};
  const Lanes parent_upper = {upper.x, upper.y, upper.z, 0.0f, upper.x, upper.y, upper.z, 0.0f};
  const Lanes step = (parent_upper - parent_lower) * 0.0625f;
  const Words words = {first, first, first, first, second, second, second, second};
  const Words shift = {0, 4, 8, 0, 0, 4, 8, 0};
  const Lanes low = __builtin_convertvector((words >> shift) & 15u, Lanes);
  const Lanes high = __builtin_convertvector((words >> (shift + 12u)) & 15u, Lanes);
  const Lanes child_lower = parent_lower + low * step;
  const Lanes child_upper = parent_upper - high * step;

  const glm::vec3 &o = ray.origin, &inverse = ray.inverse_direction;
  const Lanes origin = {o.x, o.y, o.z, 0.0f, o.x, o.y, o.z, 0.0f};
  const Lanes inverse_direction = {inverse.x, inverse.y, inverse.z, 0.0f, inverse.x, inverse.y, inverse.z, 0.0f};
  const Lanes t0 = (child_lower - origin) * inverse_direction;
  const Lanes t1 = (child_upper - origin) * inverse_direction;
  const auto swapped = t0 > t1;  // clip_slab's swap; a NaN lane keeps its order and is ignored below
  const Lanes near = swapped ? t1 : t0;
  const Lanes far = (swapped ? t0 : t1) * kSlabFarScale;

  ChildPair pair;
  for (int k = 0; k < 2; ++k) {
    float entry = tmin, exit = tmax;
    for (int axis = 0; axis < 3; ++axis) {
      const int lane = 4 * k + axis;
      pair.box[k].lower[axis] = child_lower[lane];
      pair.box[k].upper[axis] = child_upper[lane];
      entry = near[lane] > entry ? near[lane] : entry;
      exit = far[lane] < exit ? far[lane] : exit;
    }
    pair.distance[k] = entry <= exit ? entry : std::numeric_limits<float>::infinity();
  }
  return pair;
}

}  // namespace wavetrace::hmq
