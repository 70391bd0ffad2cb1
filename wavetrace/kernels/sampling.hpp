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

// sin and cos of 2 pi `turns` for turns in [0, 1], without a libm call per sample: the
// nearest quarter turn is taken out exactly, and the rest, within pi/4, goes through
// Taylor polynomials to degree 9 (sin) and 8 (cos), whose error there is under 3e-8.
struct SinCos {
  float sin, cos;
};
inline SinCos sin_cos_turns(float turns) {
  const float quarters = turns * 4.0f;
  const int quarter = static_cast<int>(quarters + 0.5f);  // nearest, as turns >= 0
  const float x = (quarters - float(quarter)) * (0.5f * kPi);
  const float x2 = x * x;
  const float s = x * (1.0f + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040 + x2 * (1.0f / 362880)))));
  const float c = 1.0f + x2 * (-0.5f + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320))));
  // Rotate by the quarter turns taken out, with selects rather than a switch so that loops
  // over many samples vectorize: odd quarters swap sin and cos, and the signs follow.
  const bool odd = (quarter & 1) != 0;
  const float sine = odd ? c : s, cosine = odd ? s : c;
  return {(quarter & 2) ? -sine : sine, ((quarter + 1) & 2) ? -cosine : cosine};
}

// Cosine-weighted direction in the hemisphere around n; pdf = cos(theta) / pi. Written out
// in floats (basis_around's frame, the same operations) so that loops over rays vectorize,
// which the vec3 temporaries of the frame kept the compiler from doing.
inline glm::vec3 cosine_hemisphere(glm::vec3 n, float u1, float u2) {
  const float radius = std::sqrt(u1);
  const SinCos phi = sin_cos_turns(u2);
  const float x = radius * phi.cos;
  const float y = radius * phi.sin;
  const float z = std::sqrt(std::max(0.0f, 1.0f - u1));  // (fmax, with its NaN rule, does not vectorize)
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  const float tangent_x = 1.0f + sign * n.x * n.x * a, tangent_y = sign * b, tangent_z = -sign * n.x;
  const float bitangent_x = b, bitangent_y = sign + n.y * n.y * a, bitangent_z = -n.y;
  return {tangent_x * x + bitangent_x * y + n.x * z, tangent_y * x + bitangent_y * y + n.y * z,
          tangent_z * x + bitangent_z * y + n.z * z};
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
