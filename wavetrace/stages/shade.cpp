// Film contributions and Russian roulette, one pass over the batch.
#include "wavetrace/stages/shade.hpp"

#include <glm/geometric.hpp>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/stages/escaped_light.hpp"

namespace wavetrace {

void ShadeStage::process(Batch* batch, StageOutput& out) const {
  if (shade(*batch, batch->rays.all()) == 0) {
    out.release(batch);
  } else {
    out.emit(batch);
  }
}

std::size_t ShadeStage::shade(Batch& batch, RayRange range) const {
  RayBatch& rays = batch.rays;
  const HitBatch& hits = batch.hits;
  const Scene& scene = world_.scene;
  std::size_t survivors = 0;
  for (std::size_t i = range.begin; i < range.end; ++i) {
    if (!(rays.flags[i] & ray_flags::alive)) continue;
    if (!hits.is_hit(i)) {
      add_escaped_ray_light(film_, rays, i, scene.background);
      rays.flags[i] = 0;
      continue;
    }
    if (rays.kind[i] == RayKind::shadow) {  // occluded
      rays.flags[i] = 0;
      continue;
    }
    const glm::vec3 throughput(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]);
    const Material& material = scene.materials[hits.material[i]];
    if (material.emissive() && sees_emission(rays.kind[i])) {
      // Bounce rays do not count emission: next-event estimation already sampled the lights.
      const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
      if (glm::dot(hits.normal(i), direction) < 0.0f) {
        const glm::vec3 light = throughput * material.emission;
        film_.add(rays.pixel[i], light.r, light.g, light.b);
      }
    }
    if (material.albedo == glm::vec3(0.0f)) {
      rays.flags[i] = 0;
      continue;
    }
    bool continues = rules_.may_bounce(rays.depth[i]);
    if (continues && rules_.roulette_applies(rays.depth[i])) {
      const float u = unit_float32(
          path_draw(path_key(rays.pixel[i], rays.sample[i]), rays.depth[i], RandomPurpose::russian_roulette));
      continues = u < survival_probability(material.albedo);
    }
    rays.flags[i] = continues ? std::uint8_t(ray_flags::alive | ray_flags::continues) : ray_flags::alive;
    ++survivors;
  }
  return survivors;
}

}  // namespace wavetrace
