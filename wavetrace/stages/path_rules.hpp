// Rules of the diffuse path tracer shared by shade and spawn, so the two agree exactly.
#pragma once

#include <algorithm>
#include <cstdint>

#include <glm/vec3.hpp>

namespace wavetrace {

struct PathRules {
  std::uint32_t max_depth = 5;               // bounce rays have depth 1..max_depth
  std::uint32_t russian_roulette_depth = 3;  // bounce depth from which paths may be ended

  bool may_bounce(std::uint32_t depth) const { return depth + 1 <= max_depth; }
  bool roulette_applies(std::uint32_t depth) const { return depth + 1 >= russian_roulette_depth; }
  bool operator==(const PathRules&) const = default;
};

// Probability that a path continues past a surface of this albedo under Russian roulette.
inline float survival_probability(const glm::vec3& albedo) {
  return std::clamp(std::max({albedo.x, albedo.y, albedo.z}), 0.05f, 0.95f);
}

}  // namespace wavetrace
