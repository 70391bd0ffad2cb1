// Filling a closest hit's point and normal (HitBatch::set_surface) from the triangle an
// accelerator found: read from the mesh it traces in place, or from corners it decoded
// from a strip, whose order must first be turned back into the mesh's winding.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/vec3.hpp>

#include "wavetrace/memory/ray_batch.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

inline void set_surface_from_mesh(HitBatch& hits, std::size_t ray, const TriangleMesh& mesh, std::uint32_t triangle) {
  const glm::uvec3& corners = mesh.triangles[triangle];
  hits.set_surface(ray, mesh.positions[corners.x], mesh.positions[corners.y], mesh.positions[corners.z]);
}

// The surfaces of a range's closest hits, read from the mesh a few rays ahead of their use:
// each hit's corners are two dependent cache misses (index, then vertices), and over a
// batch they overlap instead of following one another.
inline void set_surfaces_from_mesh(HitBatch& hits, RayRange range, const TriangleMesh& mesh) {
  constexpr std::uint32_t kIndexAhead = 8, kVertexAhead = 4;
  const glm::uvec3* triangles = mesh.triangles.data();
  const glm::vec3* positions = mesh.positions.data();
  for (std::uint32_t i = range.begin; i < range.end; ++i) {
    if (i + kIndexAhead < range.end && hits.is_hit(i + kIndexAhead)) {
      __builtin_prefetch(triangles + hits.primitive[i + kIndexAhead]);
    }
    if (i + kVertexAhead < range.end && hits.is_hit(i + kVertexAhead)) {
      const glm::uvec3& corners = triangles[hits.primitive[i + kVertexAhead]];
      __builtin_prefetch(positions + corners.x);
      __builtin_prefetch(positions + corners.y);
      __builtin_prefetch(positions + corners.z);
    }
    if (hits.is_hit(i)) set_surface_from_mesh(hits, i, mesh, hits.primitive[i]);
  }
}

// `strip_corner` holds the triangle's corners in strip order; `code` is the strip formats'
// corner code: the mesh's second corner is strip corner code / 3, its third code % 3 (and
// the first the remaining one), the same code that maps the barycentrics back.
inline void set_surface_from_strip(HitBatch& hits, std::size_t ray, const glm::vec3 (&strip_corner)[3], std::uint32_t code) {
  const std::uint32_t second = code / 3, third = code % 3;
  // The first corner is the one left, 3 - second - third; taken modulo 3 so that a code of
  // two equal corners (a strip's repeated triangle, or a crafted world file) stays in range.
  hits.set_surface(ray, strip_corner[(3 - second - third) % 3], strip_corner[second], strip_corner[third]);
}

}  // namespace wavetrace
