// The light a ray brings when it hits nothing: the sky for camera and bounce rays, the
// carried light sample for an unoccluded shadow ray. Shared by shade and by approx_hit,
// which ends rays that miss the scene's box.
#pragma once

#include <glm/vec3.hpp>

#include "wavetrace/memory/ray_batch.hpp"
#include "wavetrace/stages/film.hpp"

namespace wavetrace {

inline void add_escaped_ray_light(Film& film, const RayBatch& rays, std::size_t i, const glm::vec3& background) {
  const glm::vec3 throughput(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]);
  const glm::vec3 light = rays.kind[i] == RayKind::shadow ? throughput : throughput * background;
  film.add(rays.pixel[i], light.r, light.g, light.b);
}

}  // namespace wavetrace
