// The batch loop every single-ray traversal plugs into (after madmann91/bvh's
// traverse_top_down): dead rays get their miss, live ones are loaded with their slab and
// watertight set-ups, and the traversal, always inlined, answers for one ray at a time.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

// One live ray of a batch. What a traversal leaves unused (Embree's wrapper uses neither
// set-up) is never computed: the loop and the set-ups inline, and the compiler drops it.
struct SingleRay {
  glm::vec3 origin;
  glm::vec3 direction;
  float tmin;
  float tmax;
  BoxRay box;             // slab tests against boxes
  WatertightRay sheared;  // watertight triangle tests
};

[[gnu::always_inline]] inline SingleRay load_ray(const RayBatch& rays, std::uint32_t i) {
  const glm::vec3 origin(rays.origin_x[i], rays.origin_y[i], rays.origin_z[i]);
  const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
  return {origin, direction, rays.tmin[i], rays.tmax[i], make_box_ray(origin, direction),
          make_watertight_ray(origin, direction)};
}

// Calls `trace(ray, i)` for each live ray i of the range; it writes ray i's hit or miss.
template <typename Trace>
[[gnu::always_inline]] inline void for_each_ray(const RayBatch& rays, HitBatch& hits, RayRange range, Trace&& trace) {
  for (std::uint32_t i = range.begin; i < range.end; ++i) {
    if (!(rays.flags[i] & ray_flags::alive)) {
      hits.set_miss(i);
      continue;
    }
    trace(load_ray(rays, i), i);
  }
}

}  // namespace wavetrace
