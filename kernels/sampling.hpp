// Sample warps used by the path tracer and the benchmarks: cosine-weighted hemisphere,
// uniform sphere and triangle points, and an orthonormal basis around a normal.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>
#include <glm/geometric.hpp>

namespace wavetrace {

inline constexpr float kPi = 3.14159265358979323846f;

// Duff et al. 2017, "Building an Orthonormal Basis, Revisited": no branch on a threshold,
// continuous everywhere but the pole sign flip.
struct OrthonormalBasis {
  glm::vec3 tangent, bitangent, normal;
};
inline OrthonormalBasis basis_around(const glm::vec3& n) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  return {glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x),
          glm::vec3(b, sign + n.y * n.y * a, -n.y), n};
}

// Cosine-weighted direction in the hemisphere around n; pdf = cos(theta) / pi.
inline glm::vec3 cosine_hemisphere(const glm::vec3& n, float u1, float u2) {
  const float radius = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float x = radius * std::cos(phi);
  const float y = radius * std::sin(phi);
  const float z = std::sqrt(std::fmax(0.0f, 1.0f - u1));
  const OrthonormalBasis basis = basis_around(n);
  return basis.tangent * x + basis.bitangent * y + basis.normal * z;
}

// A uniformly distributed unit vector (Archimedes: z uniform in [-1, 1], longitude uniform).
inline glm::vec3 uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1, phi = 2.0f * kPi * u2;
  const float ring = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {ring * std::cos(phi), ring * std::sin(phi), z};
}

// Barycentric coordinates (b1, b2) of a uniformly distributed point on a triangle.
struct Barycentrics {
  float b1, b2;
};
inline Barycentrics uniform_triangle(float u1, float u2) {
  const float root = std::sqrt(u1);
  return {1.0f - root, u2 * root};
}

}  // namespace wavetrace
