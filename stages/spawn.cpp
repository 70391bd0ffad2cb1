// Next-event estimation and bounce sampling for a diffuse path tracer.
#include "stages/spawn.hpp"

#include <limits>

#include <glm/geometric.hpp>

#include "kernels/random.hpp"
#include "kernels/ray_offset.hpp"
#include "kernels/sampling.hpp"

namespace wavetrace {
namespace {

// Shadow rays stop this fraction short of the light so they do not hit the light itself.
constexpr float kShadowRayShortening = 1e-4f;

void write_ray(RayBatch& to, std::size_t slot, const RayBatch& parent, std::size_t i, const glm::vec3& origin,
               const glm::vec3& direction, float tmax, RayKind kind, std::uint16_t depth, const glm::vec3& throughput) {
  to.set_geometry(slot, origin, direction, 0.0f, tmax);
  to.pixel[slot] = parent.pixel[i];
  to.sample[slot] = parent.sample[i];
  to.depth[slot] = depth;
  to.kind[slot] = kind;
  to.throughput_r[slot] = throughput.r;
  to.throughput_g[slot] = throughput.g;
  to.throughput_b[slot] = throughput.b;
  to.flags[slot] = ray_flags::alive;
}

}  // namespace

void SpawnStage::process(Batch* batch, StageOutput& out) const {
  Batch* bounces = out.acquire();
  Batch* shadows = world_.lights.empty() ? nullptr : out.acquire();
  spawn(*batch, batch->rays.all(), bounces->rays, shadows != nullptr ? &shadows->rays : nullptr);
  out.release(batch);
  for (Batch* made : {bounces, shadows}) {
    if (made == nullptr) continue;
    if (made->rays.count == 0) {
      out.release(made);
    } else {
      out.emit(made);
    }
  }
}

void SpawnStage::spawn(const Batch& batch, RayRange range, RayBatch& bounces, RayBatch* shadows) const {
  const RayBatch& rays = batch.rays;
  const HitBatch& hits = batch.hits;
  const bool has_lights = shadows != nullptr && !world_.lights.empty();
  for (std::size_t i = range.begin; i < range.end; ++i) {
    if (!(rays.flags[i] & ray_flags::alive)) continue;
    // The accelerator's point is from barycentrics rather than origin + t * direction:
    // exact to the triangle's plane.
    const glm::vec3 point = hits.point(i);
    const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
    glm::vec3 normal = glm::normalize(hits.normal(i));
    if (glm::dot(normal, direction) > 0.0f) normal = -normal;  // two-sided: face the incoming ray
    const glm::vec3 origin = offset_ray_origin(point, normal);
    const glm::vec3 albedo = world_.scene.materials[hits.material[i]].albedo;
    const glm::vec3 throughput(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]);
    const std::uint32_t depth = rays.depth[i];
    const std::uint64_t path = path_key(rays.pixel[i], rays.sample[i]);

    if (has_lights) {
      const float choice = unit_float(path_random_bits(path, depth, RandomPurpose::light_choice));
      const UnitPair uv = unit_pair(path_random_bits(path, depth, RandomPurpose::light_point));
      const LightSample light = world_.lights.sample(choice, uv.first, uv.second);
      const glm::vec3 to_light = light.point - origin;
      const float distance_squared = glm::dot(to_light, to_light);
      const float distance = std::sqrt(distance_squared);
      const glm::vec3 toward = to_light * (1.0f / distance);
      const float cos_surface = glm::dot(normal, toward);
      const float cos_light = -glm::dot(light.normal, toward);
      if (cos_surface > 0.0f && cos_light > 0.0f && distance_squared > 0.0f) {
        const glm::vec3 carried = throughput * albedo * (1.0f / kPi) * light.emission *
                                  (cos_surface * cos_light / (distance_squared * light.pdf_area));
        RayBatch& to = *shadows;
        write_ray(to, to.count++, rays, i, origin, toward, distance * (1.0f - kShadowRayShortening),
                  RayKind::shadow, static_cast<std::uint16_t>(depth), carried);
      }
    }

    if (rays.flags[i] & ray_flags::continues) {
      const UnitPair uv = unit_pair(path_random_bits(path, depth, RandomPurpose::bounce_direction));
      const glm::vec3 bounce = cosine_hemisphere(normal, uv.first, uv.second);
      // Cosine-weighted sampling of a Lambertian surface: f cos / pdf = albedo.
      glm::vec3 next = throughput * albedo;
      if (rules_.roulette_applies(depth)) next /= survival_probability(albedo);
      RayBatch& to = bounces;
      write_ray(to, to.count++, rays, i, origin, bounce, std::numeric_limits<float>::infinity(), RayKind::bounce,
                static_cast<std::uint16_t>(depth + 1), next);
    }
  }
}

}  // namespace wavetrace
