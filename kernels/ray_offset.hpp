// Moving a secondary ray's origin off the surface it leaves, by a few float ulps along
// the normal (Wächter and Binder, Ray Tracing Gems ch. 6): scale-independent, unlike a
// fixed epsilon, so it works for scenes of any size.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>

namespace wavetrace {

inline glm::vec3 offset_ray_origin(const glm::vec3& point, const glm::vec3& normal) {
  constexpr float kOrigin = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  glm::vec3 result;
  for (int axis = 0; axis < 3; ++axis) {
    const auto offset = static_cast<std::int32_t>(kIntScale * normal[axis]);
    const std::int32_t bits = std::bit_cast<std::int32_t>(point[axis]);
    const float moved = std::bit_cast<float>(bits + (point[axis] < 0.0f ? -offset : offset));
    result[axis] = std::fabs(point[axis]) < kOrigin ? point[axis] + kFloatScale * normal[axis] : moved;
  }
  return result;
}

}  // namespace wavetrace
