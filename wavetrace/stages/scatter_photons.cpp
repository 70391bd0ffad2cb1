// Deposit, roulette and bounce of each photon, one pass over the batch. A photon's kind says
// what brought it: bounce after a diffuse surface (or straight from the light), specular when
// every surface since the light was a mirror or glass (a caustic photon).
#include "wavetrace/stages/scatter_photons.hpp"

#include <limits>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/stages/spawn.hpp"

namespace wavetrace {

void ScatterPhotonsStage::process(Batch* batch, StageOutput& out) const {
  const RayBatch& rays = batch->rays;
  const HitBatch& hits = batch->hits;
  const std::vector<Material>& materials = world_.scene.materials;
  Batch* next = out.acquire();
  RayBatch& bounced = next->rays;
  for (std::size_t i = 0; i < rays.count; ++i) {
    if (!(rays.flags[i] & ray_flags::alive) || !hits.is_hit(i)) continue;
    const Material& material = materials[hits.material[i]];
    if (material.albedo == glm::vec3(0.0f)) continue;
    const std::uint32_t depth = rays.depth[i];
    const glm::vec3 incoming =
        glm::normalize(glm::vec3(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]));
    const glm::vec3 outward = glm::normalize(hits.normal(i));
    const glm::vec3 facing = glm::dot(outward, incoming) > 0.0f ? -outward : outward;
    const glm::vec3 power(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]);
    const glm::vec3 point = hits.point(i);
    const bool caustic_path = rays.kind[i] == RayKind::specular;
    if (!material.specular()) {
      deposits_.add(PhotonDeposits::key(rays.pixel[i], depth), Photon{point, power, facing}, caustic_path);
    }
    if (!rules_.may_bounce(depth)) continue;
    const std::uint64_t key = path_key(rays.pixel[i], rays.sample[i]);
    const float survival = survival_probability(material.albedo);
    if (unit_float32(path_draw(key, depth, RandomPurpose::russian_roulette)) >= survival) continue;

    glm::vec3 direction;
    RayKind kind = RayKind::bounce;
    if (material.specular()) {
      direction = scatter_specular(material, incoming, outward, key, depth).direction;
      // Straight from the light (depth 0) or by specular surfaces alone: still a caustic path.
      if (depth == 0 || caustic_path) kind = RayKind::specular;
    } else {
      direction = cosine_hemisphere(facing, unit_float32(path_draw(key, depth, RandomPurpose::bounce_direction, 0)),
                                    unit_float32(path_draw(key, depth, RandomPurpose::bounce_direction, 1)));
    }
    const glm::vec3 side = glm::dot(direction, outward) > 0.0f ? outward : -outward;
    const glm::vec3 carried = power * material.albedo / survival;
    const std::size_t slot = bounced.count++;
    bounced.set_geometry(slot, offset_ray_origin(point, side), direction, 0.0f, std::numeric_limits<float>::infinity());
    bounced.pixel[slot] = rays.pixel[i];
    bounced.sample[slot] = rays.sample[i];
    bounced.depth[slot] = static_cast<std::uint16_t>(depth + 1);
    bounced.kind[slot] = kind;
    bounced.throughput_r[slot] = carried.r;
    bounced.throughput_g[slot] = carried.g;
    bounced.throughput_b[slot] = carried.b;
    bounced.flags[slot] = ray_flags::alive;
  }
  out.release(batch);
  if (bounced.count == 0) {
    out.release(next);
  } else {
    out.emit(next);
  }
}

}  // namespace wavetrace
