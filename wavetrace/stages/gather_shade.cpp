// The path tracer's shading, then the photon maps' radiance estimates at diffuse hits:
// L = albedo / pi * E, with E the k-nearest irradiance estimate.
#include "wavetrace/stages/gather_shade.hpp"

#include <glm/geometric.hpp>

#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {

void GatherShadeStage::process(Batch* batch, StageOutput& out) const {
  RayBatch& rays = batch->rays;
  const HitBatch& hits = batch->hits;
  std::size_t survivors = path_.shade(*batch, rays.all());
  for (std::size_t i = 0; i < rays.count; ++i) {
    if (!(rays.flags[i] & ray_flags::alive)) continue;  // alive now: hits of camera, specular or gathering rays
    const Material& material = world_.scene.materials[hits.material[i]];
    if (material.specular()) continue;  // shaded as the path tracer does: it bounces on
    const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
    const glm::vec3 normal = glm::normalize(hits.normal(i));
    const glm::vec3 facing = glm::dot(normal, direction) > 0.0f ? -normal : normal;
    const bool gathering = rays.kind[i] == RayKind::bounce;
    const glm::vec3 irradiance = gathering
                                     ? maps_.global.precomputed_irradiance(hits.point(i), facing, maps_.k, maps_.radius)
                                     : maps_.caustic.irradiance(hits.point(i), facing, maps_.k, maps_.radius);
    const glm::vec3 light = glm::vec3(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]) *
                            material.albedo * (1.0f / kPi) * irradiance;
    film_.add(rays.pixel[i], light.r, light.g, light.b);
    if (gathering) {
      rays.flags[i] = 0;
      --survivors;
    } else {
      // A camera path gathers wherever it may still bounce; no roulette, since gathering ends
      // the path one step on.
      rays.flags[i] = rules_.may_bounce(rays.depth[i]) ? std::uint8_t(ray_flags::alive | ray_flags::continues)
                                                       : ray_flags::alive;
    }
  }
  if (survivors == 0) {
    out.release(batch);
  } else {
    out.emit(batch);
  }
}

}  // namespace wavetrace
