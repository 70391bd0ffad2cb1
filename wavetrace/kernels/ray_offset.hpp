// Moving a secondary ray's origin off the surface it leaves, by a few float ulps along
// the normal (Wächter and Binder, Ray Tracing Gems ch. 6): scale-independent, unlike a
// fixed epsilon, so it works for scenes of any size.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>

namespace wavetrace {

// One coordinate: branch-free, so loops over a batch's rays vectorize.
inline float offset_coordinate(float point, float normal) {
  constexpr float kOrigin = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  const auto offset = static_cast<std::int32_t>(kIntScale * normal);
  const std::int32_t bits = std::bit_cast<std::int32_t>(point);
  const float moved = std::bit_cast<float>(bits + (point < 0.0f ? -offset : offset));
  const float nudged = point + kFloatScale * normal;  // both computed: a select, not a branch
  return std::fabs(point) < kOrigin ? nudged : moved;
}

inline glm::vec3 offset_ray_origin(const glm::vec3& point, const glm::vec3& normal) {
  return {offset_coordinate(point.x, normal.x), offset_coordinate(point.y, normal.y),
          offset_coordinate(point.z, normal.z)};
}

}  // namespace wavetrace
