// Next-event estimation and bounce sampling for a path tracer: diffuse surfaces in vectorized
// chunks, mirrors and glass one ray at a time.
#include "wavetrace/stages/spawn.hpp"

#include <limits>
#include <vector>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"

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

SpecularScatter scatter_specular(const Material& material, const glm::vec3& incoming, const glm::vec3& outward,
                                 std::uint64_t path, std::uint32_t depth) {
  if (material.surface != Surface::glass) return {reflect_direction(incoming, outward), false};
  return glass_scatter(incoming, outward, material.ior,
                       unit_float32(path_draw(path, depth, RandomPurpose::fresnel_choice)));
}

void write_specular_bounce(const RayBatch& rays, const HitBatch& hits, std::size_t i, const Material& material,
                           const PathRules& rules, RayBatch& bounces, RayKind kind) {
  const glm::vec3 incoming =
      glm::normalize(glm::vec3(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]));
  const glm::vec3 outward = glm::normalize(hits.normal(i));
  const SpecularScatter scatter =
      scatter_specular(material, incoming, outward, path_key(rays.pixel[i], rays.sample[i]), rays.depth[i]);
  // The origin moves off the surface to the side the new ray leaves on.
  const glm::vec3 side = glm::dot(scatter.direction, outward) > 0.0f ? outward : -outward;
  const glm::vec3 throughput(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]);
  glm::vec3 weight = throughput * material.albedo;
  if (rules.roulette_applies(rays.depth[i])) weight /= survival_probability(material.albedo);
  write_ray(bounces, bounces.count++, rays, i, offset_ray_origin(hits.point(i), side), scatter.direction,
            std::numeric_limits<float>::infinity(), kind, static_cast<std::uint16_t>(rays.depth[i] + 1), weight);
}

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

namespace {

// A chunk of live rays compacted into dense columns: the loops over it carry no gather and
// no branch but selects, so the compiler runs them eight rays at a time. Whatever the
// chunk's size, each ray's arithmetic is the same IEEE operations (contraction is off), so
// the megakernel's one-ray chunks make bit for bit the wavefront's rays.
struct SpawnChunk {
  static constexpr std::uint32_t kCapacity = 64;
  std::uint32_t count = 0;
  alignas(64) std::uint32_t ray[kCapacity];  // index in the parent batch
  alignas(64) std::uint32_t depth[kCapacity];
  alignas(64) std::uint32_t path_high[kCapacity];  // the path's key (path_key), in halves
  alignas(64) std::uint32_t path_low[kCapacity];
  alignas(64) float point[3][kCapacity];
  alignas(64) float incoming[3][kCapacity];
  alignas(64) float normal[3][kCapacity];  // unnormalized on entry, then unit and facing the incoming ray
  alignas(64) float weight[3][kCapacity];  // throughput x albedo
  alignas(64) float origin[3][kCapacity];
  // The light sample (point, normal, emission, pdf) and what it carries back.
  alignas(64) float light_u[3][kCapacity];
  alignas(64) float light_point[3][kCapacity];
  alignas(64) float light_normal[3][kCapacity];
  alignas(64) float light_emission[3][kCapacity];
  alignas(64) float light_pdf[kCapacity];
  alignas(64) float toward[3][kCapacity];
  alignas(64) float shadow_tmax[kCapacity];
  alignas(64) float carried[3][kCapacity];
  alignas(64) bool shadow_valid[kCapacity];
  alignas(64) float bounce[3][kCapacity];
};

}  // namespace

void SpawnStage::spawn(const Batch& batch, RayRange range, RayBatch& bounces, RayBatch* shadows) const {
  const RayBatch& rays = batch.rays;
  const HitBatch& hits = batch.hits;
  const bool has_lights = shadows != nullptr && !world_.lights.empty();
  const std::vector<Material>& materials = world_.scene.materials;
  SpawnChunk c;
  std::uint32_t next = range.begin;
  while (next < range.end) {
    // Compact: the next live rays' inputs, gathered once.
    c.count = 0;
    for (; next < range.end && c.count < SpawnChunk::kCapacity; ++next) {
      if (!(rays.flags[next] & ray_flags::alive)) continue;
      const Material& material = materials[hits.material[next]];
      if (material.specular()) {  // rare beside diffuse hits: one ray at a time, outside the chunk
        if (rays.flags[next] & ray_flags::continues) {
          write_specular_bounce(rays, hits, next, material, rules_, bounces, RayKind::specular);
        }
        continue;
      }
      const std::uint32_t k = c.count++;
      c.ray[k] = next;
      c.depth[k] = rays.depth[next];
      const std::uint64_t path = path_key(rays.pixel[next], rays.sample[next]);
      c.path_high[k] = std::uint32_t(path >> 32);
      c.path_low[k] = std::uint32_t(path);
      // The accelerator's point is from barycentrics rather than origin + t * direction:
      // exact to the triangle's plane.
      c.point[0][k] = hits.point_x[next];
      c.point[1][k] = hits.point_y[next];
      c.point[2][k] = hits.point_z[next];
      c.incoming[0][k] = rays.direction_x[next];
      c.incoming[1][k] = rays.direction_y[next];
      c.incoming[2][k] = rays.direction_z[next];
      c.normal[0][k] = hits.normal_x[next];
      c.normal[1][k] = hits.normal_y[next];
      c.normal[2][k] = hits.normal_z[next];
      const glm::vec3& albedo = material.albedo;
      c.weight[0][k] = rays.throughput_r[next] * albedo.x;
      c.weight[1][k] = rays.throughput_g[next] * albedo.y;
      c.weight[2][k] = rays.throughput_b[next] * albedo.z;
    }
    const std::uint32_t n = c.count;

    // The surface: a unit normal facing the incoming ray (two-sided), the offset origin,
    // and the path's random draws.
    for (std::uint32_t k = 0; k < n; ++k) {
      const float x = c.normal[0][k], y = c.normal[1][k], z = c.normal[2][k];
      const float inverse_length = 1.0f / std::sqrt(x * x + y * y + z * z);
      const float facing = x * c.incoming[0][k] + y * c.incoming[1][k] + z * c.incoming[2][k];
      const float scale = facing > 0.0f ? -inverse_length : inverse_length;
      c.normal[0][k] = x * scale;
      c.normal[1][k] = y * scale;
      c.normal[2][k] = z * scale;
      c.origin[0][k] = offset_coordinate(c.point[0][k], x * scale);
      c.origin[1][k] = offset_coordinate(c.point[1][k], y * scale);
      c.origin[2][k] = offset_coordinate(c.point[2][k], z * scale);
      c.light_u[0][k] = unit_float32(path_draw(c.path_high[k], c.path_low[k], c.depth[k], RandomPurpose::light_choice));
      c.light_u[1][k] = unit_float32(path_draw(c.path_high[k], c.path_low[k], c.depth[k], RandomPurpose::light_point, 0));
      c.light_u[2][k] = unit_float32(path_draw(c.path_high[k], c.path_low[k], c.depth[k], RandomPurpose::light_point, 1));
    }

    if (has_lights) {
      // The light samples: a table lookup per ray, kept apart from the arithmetic.
      for (std::uint32_t k = 0; k < n; ++k) {
        const LightSample light = world_.lights.sample(c.light_u[0][k], c.light_u[1][k], c.light_u[2][k]);
        for (int axis = 0; axis < 3; ++axis) {
          c.light_point[axis][k] = light.point[axis];
          c.light_normal[axis][k] = light.normal[axis];
          c.light_emission[axis][k] = light.emission[axis];
        }
        c.light_pdf[k] = light.pdf_area;
      }
      for (std::uint32_t k = 0; k < n; ++k) {
        const glm::vec3 to_light(c.light_point[0][k] - c.origin[0][k], c.light_point[1][k] - c.origin[1][k],
                                 c.light_point[2][k] - c.origin[2][k]);
        const float distance_squared = glm::dot(to_light, to_light);
        const float distance = std::sqrt(distance_squared);
        const glm::vec3 toward = to_light * (1.0f / distance);
        const float cos_surface = c.normal[0][k] * toward.x + c.normal[1][k] * toward.y + c.normal[2][k] * toward.z;
        const float cos_light =
            -(c.light_normal[0][k] * toward.x + c.light_normal[1][k] * toward.y + c.light_normal[2][k] * toward.z);
        c.shadow_valid[k] = (cos_surface > 0.0f) & (cos_light > 0.0f) & (distance_squared > 0.0f);
        const float geometry = cos_surface * cos_light / (distance_squared * c.light_pdf[k]);
        for (int axis = 0; axis < 3; ++axis) {
          c.toward[axis][k] = toward[axis];
          c.carried[axis][k] = c.weight[axis][k] * (1.0f / kPi) * c.light_emission[axis][k] * geometry;
        }
        c.shadow_tmax[k] = distance * (1.0f - kShadowRayShortening);
      }
    }

    // Cosine-weighted bounces (f cos / pdf = albedo for a Lambertian surface).
    for (std::uint32_t k = 0; k < n; ++k) {
      const float u1 = unit_float32(path_draw(c.path_high[k], c.path_low[k], c.depth[k], RandomPurpose::bounce_direction, 0));
      const float u2 = unit_float32(path_draw(c.path_high[k], c.path_low[k], c.depth[k], RandomPurpose::bounce_direction, 1));
      const glm::vec3 bounce = cosine_hemisphere({c.normal[0][k], c.normal[1][k], c.normal[2][k]}, u1, u2);
      c.bounce[0][k] = bounce.x;
      c.bounce[1][k] = bounce.y;
      c.bounce[2][k] = bounce.z;
    }

    // Out: each ray's shadow ray and, if its path continues, its bounce, in ray order.
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t i = c.ray[k];
      const auto depth = static_cast<std::uint16_t>(c.depth[k]);
      const glm::vec3 origin(c.origin[0][k], c.origin[1][k], c.origin[2][k]);
      if (has_lights && c.shadow_valid[k]) {
        write_ray(*shadows, shadows->count++, rays, i, origin, {c.toward[0][k], c.toward[1][k], c.toward[2][k]},
                  c.shadow_tmax[k], RayKind::shadow, depth, {c.carried[0][k], c.carried[1][k], c.carried[2][k]});
      }
      if (rays.flags[i] & ray_flags::continues) {
        glm::vec3 next_weight(c.weight[0][k], c.weight[1][k], c.weight[2][k]);
        if (rules_.roulette_applies(depth)) {
          next_weight /= survival_probability(materials[hits.material[i]].albedo);
        }
        write_ray(bounces, bounces.count++, rays, i, origin, {c.bounce[0][k], c.bounce[1][k], c.bounce[2][k]},
                  std::numeric_limits<float>::infinity(), RayKind::bounce, static_cast<std::uint16_t>(depth + 1),
                  next_weight);
      }
    }
  }
}

}  // namespace wavetrace
