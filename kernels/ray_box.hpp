// Ray against axis-aligned box, slab test with precomputed reciprocal directions.
//
// Robustness (after Ize, "Robust BVH Ray Traversal", JCGT 2013): the far distance of each
// slab is scaled by 1 + 2 gamma(3), which bounds the float error of the slab arithmetic,
// so a box is never missed by a ray that grazes its surface. A zero direction component
// would make (plane - origin) * (1/0) a NaN when the origin lies on the plane; replacing
// it by a signed tiny value keeps every product finite and the test conservative (an
// origin on the plane counts as inside that slab).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>

namespace wavetrace {

// gamma(n) = n u / (1 - n u), u = 2^-24: bound of relative error after n float operations.
inline constexpr float kFloatUnitRoundoff = 0.5f * 1.1920928955078125e-7f;
constexpr float float_error_gamma(int n) { return n * kFloatUnitRoundoff / (1.0f - n * kFloatUnitRoundoff); }
inline constexpr float kSlabFarScale = 1.0f + 2.0f * float_error_gamma(3);

// |direction| below this is treated as this (with its sign) when inverting.
inline constexpr float kTinyDirection = 1e-20f;

inline float safe_reciprocal(float direction) {
  return 1.0f / (std::fabs(direction) < kTinyDirection ? std::copysign(kTinyDirection, direction) : direction);
}

// One ray prepared for many box tests.
struct BoxRay {
  glm::vec3 origin;
  glm::vec3 inverse_direction;
};

inline BoxRay make_box_ray(const glm::vec3& origin, const glm::vec3& direction) {
  return {origin, glm::vec3(safe_reciprocal(direction.x), safe_reciprocal(direction.y), safe_reciprocal(direction.z))};
}

// Entry distance of the ray into [lower, upper] clipped to [tmin, tmax], or +inf on a miss.
inline float intersect_box(const BoxRay& ray, const glm::vec3& lower, const glm::vec3& upper, float tmin, float tmax) {
  const float tx0 = (lower.x - ray.origin.x) * ray.inverse_direction.x;
  const float tx1 = (upper.x - ray.origin.x) * ray.inverse_direction.x;
  const float ty0 = (lower.y - ray.origin.y) * ray.inverse_direction.y;
  const float ty1 = (upper.y - ray.origin.y) * ray.inverse_direction.y;
  const float tz0 = (lower.z - ray.origin.z) * ray.inverse_direction.z;
  const float tz1 = (upper.z - ray.origin.z) * ray.inverse_direction.z;
  const float near = std::max({std::min(tx0, tx1), std::min(ty0, ty1), std::min(tz0, tz1), tmin});
  const float far = std::min({std::max(tx0, tx1), std::max(ty0, ty1), std::max(tz0, tz1)}) * kSlabFarScale;
  return near <= std::min(far, tmax) ? near : std::numeric_limits<float>::infinity();
}

// The same test for `count` rays in SoA columns against one box; writes entry distances
// (or +inf) to `entry`. Plain loops the compiler vectorizes (AVX2 here).
inline void intersect_box_soa(const float* origin_x, const float* origin_y, const float* origin_z,
                              const float* inverse_x, const float* inverse_y, const float* inverse_z,
                              const float* tmin, const float* tmax, std::size_t count, const glm::vec3& lower,
                              const glm::vec3& upper, float* entry) {
  for (std::size_t i = 0; i < count; ++i) {
    const float tx0 = (lower.x - origin_x[i]) * inverse_x[i], tx1 = (upper.x - origin_x[i]) * inverse_x[i];
    const float ty0 = (lower.y - origin_y[i]) * inverse_y[i], ty1 = (upper.y - origin_y[i]) * inverse_y[i];
    const float tz0 = (lower.z - origin_z[i]) * inverse_z[i], tz1 = (upper.z - origin_z[i]) * inverse_z[i];
    const float near = std::max(std::max(std::min(tx0, tx1), std::min(ty0, ty1)), std::max(std::min(tz0, tz1), tmin[i]));
    const float far =
        std::min(std::min(std::max(tx0, tx1), std::max(ty0, ty1)), std::max(tz0, tz1)) * kSlabFarScale;
    entry[i] = near <= std::min(far, tmax[i]) ? near : std::numeric_limits<float>::infinity();
  }
}

}  // namespace wavetrace
