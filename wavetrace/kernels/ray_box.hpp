// Ray against axis-aligned box, slab test with precomputed reciprocal directions.
//
// Robustness (after Ize, "Robust BVH Ray Traversal", JCGT 2013): the far distance of each
// slab is scaled by 1 + 2 gamma(3), which bounds the float error of the slab arithmetic,
// so a box is never missed by a ray that grazes its surface. A zero direction component
// has an infinite reciprocal; with the origin exactly on that slab's plane the product is
// 0 * inf = NaN, and the comparisons below are written so that a NaN bound is ignored
// (the slab does not constrain the ray, which is right: the ray runs inside the plane).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/vec3.hpp>

namespace wavetrace {

// gamma(n) = n u / (1 - n u), u = 2^-24: bound of relative error after n float operations.
inline constexpr float kFloatUnitRoundoff = 0.5f * 1.1920928955078125e-7f;
constexpr float float_error_gamma(int n) { return n * kFloatUnitRoundoff / (1.0f - n * kFloatUnitRoundoff); }
inline constexpr float kSlabFarScale = 1.0f + 2.0f * float_error_gamma(3);

// One ray prepared for many box tests.
struct BoxRay {
  glm::vec3 origin;
  glm::vec3 inverse_direction;  // 1 / direction, +-inf for zero components
};

inline BoxRay make_box_ray(const glm::vec3& origin, const glm::vec3& direction) {
  return {origin, glm::vec3(1.0f / direction.x, 1.0f / direction.y, 1.0f / direction.z)};
}

// Narrows [near, far] by one slab; `x > y ? x : y` keeps the old bound when the new one is NaN.
inline void clip_slab(float t0, float t1, float& near, float& far) {
  if (t0 > t1) std::swap(t0, t1);
  t1 *= kSlabFarScale;
  near = t0 > near ? t0 : near;
  far = t1 < far ? t1 : far;
}

// The part [near, far] of [tmin, tmax] inside the box; false on a miss.
inline bool clip_to_box(const BoxRay& ray, const glm::vec3& lower, const glm::vec3& upper, float tmin, float tmax,
                        float& near, float& far) {
  near = tmin;
  far = tmax;
  clip_slab((lower.x - ray.origin.x) * ray.inverse_direction.x, (upper.x - ray.origin.x) * ray.inverse_direction.x,
            near, far);
  clip_slab((lower.y - ray.origin.y) * ray.inverse_direction.y, (upper.y - ray.origin.y) * ray.inverse_direction.y,
            near, far);
  clip_slab((lower.z - ray.origin.z) * ray.inverse_direction.z, (upper.z - ray.origin.z) * ray.inverse_direction.z,
            near, far);
  return near <= far;
}

// Entry distance of the ray into [lower, upper] clipped to [tmin, tmax], or +inf on a miss.
inline float intersect_box(const BoxRay& ray, const glm::vec3& lower, const glm::vec3& upper, float tmin, float tmax) {
  float near = tmin, far = tmax;
  return clip_to_box(ray, lower, upper, tmin, tmax, near, far) ? near : std::numeric_limits<float>::infinity();
}

// The same test for `count` rays in SoA columns against one box; writes entry distances
// (or +inf) to `entry`. Plain loops the compiler vectorizes (AVX2 here).
inline void intersect_box_soa(const float* origin_x, const float* origin_y, const float* origin_z,
                              const float* inverse_x, const float* inverse_y, const float* inverse_z,
                              const float* tmin, const float* tmax, std::size_t count, const glm::vec3& lower,
                              const glm::vec3& upper, float* entry) {
  for (std::size_t i = 0; i < count; ++i) {
    float near = tmin[i], far = tmax[i];
    clip_slab((lower.x - origin_x[i]) * inverse_x[i], (upper.x - origin_x[i]) * inverse_x[i], near, far);
    clip_slab((lower.y - origin_y[i]) * inverse_y[i], (upper.y - origin_y[i]) * inverse_y[i], near, far);
    clip_slab((lower.z - origin_z[i]) * inverse_z[i], (upper.z - origin_z[i]) * inverse_z[i], near, far);
    entry[i] = near <= far ? near : std::numeric_limits<float>::infinity();
  }
}

// One ray against `count` boxes in SoA columns (lower[axis][k], upper[axis][k]): the same test
// as intersect_box, box by box, entry distances (or +inf) to `entry`. A plain loop the
// compiler vectorizes: a chunked world lists a ray's chunks with it.
inline void intersect_boxes_soa(const BoxRay& ray, const float* const lower[3], const float* const upper[3],
                                std::size_t count, float tmin, float tmax, float* entry) {
  for (std::size_t k = 0; k < count; ++k) {
    float near = tmin, far = tmax;
    clip_slab((lower[0][k] - ray.origin.x) * ray.inverse_direction.x,
              (upper[0][k] - ray.origin.x) * ray.inverse_direction.x, near, far);
    clip_slab((lower[1][k] - ray.origin.y) * ray.inverse_direction.y,
              (upper[1][k] - ray.origin.y) * ray.inverse_direction.y, near, far);
    clip_slab((lower[2][k] - ray.origin.z) * ray.inverse_direction.z,
              (upper[2][k] - ray.origin.z) * ray.inverse_direction.z, near, far);
    entry[k] = near <= far ? near : std::numeric_limits<float>::infinity();
  }
}

}  // namespace wavetrace
