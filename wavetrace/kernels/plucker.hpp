// Plücker edge tests: on which side of a directed edge a ray passes. Ray-Strips shares
// these between adjacent triangles of a strip (each edge tested once); a triangle is hit
// when the ray passes all three of its edges on the same side.
//
// The edge is taken relative to the ray origin, so the ray's moment vanishes and the
// permuted inner product of ray (d, o x d) and edge (b - a, a x b) reduces to
// d . ((a - o) x (b - o)): positive when the ray passes the edge counter-clockwise.
// Evaluated with the same operand order from either triangle, an edge's sign is the
// same up to negation, so adjacent triangles never both miss a ray through their edge.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "wavetrace/kernels/triangle_intersect.hpp"

namespace wavetrace {

inline float plucker_edge_side(const glm::vec3& origin, const glm::vec3& direction, const glm::vec3& a,
                               const glm::vec3& b) {
  return glm::dot(direction, glm::cross(a - origin, b - origin));
}

// A full triangle test from three Plücker edge sides (either orientation), with t from
// the plane and barycentrics from the edge sides.
inline bool intersect_plucker(const glm::vec3& origin, const glm::vec3& direction, const glm::vec3& v0,
                              const glm::vec3& v1, const glm::vec3& v2, float tmin, float tmax, TriangleHit& hit) {
  const float side12 = plucker_edge_side(origin, direction, v1, v2);  // opposite v0: weight of v0
  const float side20 = plucker_edge_side(origin, direction, v2, v0);  // weight of v1
  const float side01 = plucker_edge_side(origin, direction, v0, v1);  // weight of v2
  if ((side12 < 0.0f || side20 < 0.0f || side01 < 0.0f) && (side12 > 0.0f || side20 > 0.0f || side01 > 0.0f)) {
    return false;
  }
  const float sum = side12 + side20 + side01;
  if (sum == 0.0f) return false;
  const glm::vec3 normal = glm::cross(v1 - v0, v2 - v0);
  const float facing = glm::dot(normal, direction);
  if (facing == 0.0f) return false;
  const float t = glm::dot(normal, v0 - origin) / facing;
  if (!(t >= tmin && t <= tmax)) return false;
  const float inverse = 1.0f / sum;
  hit = {t, side20 * inverse, side01 * inverse};
  return true;
}

}  // namespace wavetrace
