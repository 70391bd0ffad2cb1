// Ray-triangle tests. Barycentrics follow Embree's convention everywhere: a hit point is
// (1 - u - v) v0 + u v1 + v v2.
//
//  * watertight: Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection", JCGT 2013.
//    The ray is sheared so it runs along +z from the origin; edge functions of the sheared
//    2D triangle decide the hit. Shared edges are evaluated identically from both
//    triangles, so no ray passes between them; exact zeros are redone in double.
//  * Möller-Trumbore (1997): faster to set up, not watertight (kept for comparison).
#pragma once

#include <cmath>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace wavetrace {

struct TriangleHit {
  float t;
  float u;
  float v;
};

// Per-ray constants of the watertight test.
struct WatertightRay {
  glm::vec3 origin;
  int kx, ky, kz;        // permutation: kz is the dominant axis of the direction
  float shear_x, shear_y, shear_z;
};

inline WatertightRay make_watertight_ray(const glm::vec3& origin, const glm::vec3& direction) {
  WatertightRay ray;
  ray.origin = origin;
  const glm::vec3 magnitude = glm::abs(direction);
  ray.kz = magnitude.x > magnitude.y ? (magnitude.x > magnitude.z ? 0 : 2) : (magnitude.y > magnitude.z ? 1 : 2);
  ray.kx = (ray.kz + 1) % 3;
  ray.ky = (ray.kx + 1) % 3;
  if (direction[ray.kz] < 0.0f) std::swap(ray.kx, ray.ky);  // keep the winding
  ray.shear_x = direction[ray.kx] / direction[ray.kz];
  ray.shear_y = direction[ray.ky] / direction[ray.kz];
  ray.shear_z = 1.0f / direction[ray.kz];
  return ray;
}

// tmax only prunes: the scaled pre-check against it is widened by this factor so that it never
// rejects a triangle whose computed t (rounded twice: 1 / det, then the product) is <= tmax;
// the decision is then made on t itself. Without the slack a triangle could pass or fail at
// t == tmax depending on the rounding of tmax * |det|, and which of two equally near hits a ray
// reports would depend on the order they were tested in (see nearest_hit.hpp).
inline constexpr float kDistancePrecheckSlack = 1.0f + 0x1p-20f;

// A hit with t in [tmin, tmax] writes `hit` and returns true. Both faces hit. Always inlined:
// GCC kept it a call in loops over decoded leaves (hmq: 8% slower, bvh unchanged).
[[gnu::always_inline]] inline bool intersect_watertight(const WatertightRay& ray, const glm::vec3& v0, const glm::vec3& v1,
                                 const glm::vec3& v2, float tmin, float tmax, TriangleHit& hit) {
  const glm::vec3 a = v0 - ray.origin, b = v1 - ray.origin, c = v2 - ray.origin;
  const float ax = a[ray.kx] - ray.shear_x * a[ray.kz], ay = a[ray.ky] - ray.shear_y * a[ray.kz];
  const float bx = b[ray.kx] - ray.shear_x * b[ray.kz], by = b[ray.ky] - ray.shear_y * b[ray.kz];
  const float cx = c[ray.kx] - ray.shear_x * c[ray.kz], cy = c[ray.ky] - ray.shear_y * c[ray.kz];
  float u = cx * by - cy * bx;  // weight of v0
  float v = ax * cy - ay * cx;  // weight of v1
  float w = bx * ay - by * ax;  // weight of v2
  if (u == 0.0f || v == 0.0f || w == 0.0f) {  // on an edge in float: decide in double
    u = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
    v = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
    w = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
  const float determinant = u + v + w;
  if (determinant == 0.0f) return false;
  const float az = ray.shear_z * a[ray.kz], bz = ray.shear_z * b[ray.kz], cz = ray.shear_z * c[ray.kz];
  const float scaled_t = u * az + v * bz + w * cz;
  // Compare t * det against the interval without dividing; the sign of det flips it.
  const float sign = std::copysign(1.0f, determinant);
  const float abs_determinant = std::fabs(determinant);
  const float signed_t = scaled_t * sign;
  if (signed_t < tmin * abs_determinant || signed_t > tmax * abs_determinant * kDistancePrecheckSlack) return false;
  const float inverse = 1.0f / determinant;
  const float t = scaled_t * inverse;
  if (t > tmax) return false;
  hit = {t, v * inverse, w * inverse};
  return true;
}

inline bool intersect_moller_trumbore(const glm::vec3& origin, const glm::vec3& direction, const glm::vec3& v0,
                                      const glm::vec3& v1, const glm::vec3& v2, float tmin, float tmax,
                                      TriangleHit& hit) {
  const glm::vec3 edge1 = v1 - v0, edge2 = v2 - v0;
  const glm::vec3 p = glm::cross(direction, edge2);
  const float determinant = glm::dot(edge1, p);
  if (determinant == 0.0f) return false;
  const float inverse = 1.0f / determinant;
  const glm::vec3 s = origin - v0;
  const float u = glm::dot(s, p) * inverse;
  if (u < 0.0f || u > 1.0f) return false;
  const glm::vec3 q = glm::cross(s, edge1);
  const float v = glm::dot(direction, q) * inverse;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float t = glm::dot(edge2, q) * inverse;
  if (t < tmin || t > tmax) return false;
  hit = {t, u, v};
  return true;
}

}  // namespace wavetrace
