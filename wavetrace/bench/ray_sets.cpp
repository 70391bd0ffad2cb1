// Ray set generation, deterministic (keyed randomness), and tracing a set in parallel.
#include "wavetrace/bench/ray_sets.hpp"

#include <optional>

#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct RayWriter {
  RaySet& set;
  std::size_t batch_size;
  void add(const glm::vec3& origin, const glm::vec3& direction, float tmax, RayKind kind, std::uint32_t id) {
    if (set.batches.empty() || set.batches.back()->count == batch_size) {
      set.batches.push_back(std::make_unique<RayBatch>(batch_size));
    }
    RayBatch& rays = *set.batches.back();
    const std::size_t i = rays.count++;
    rays.set_geometry(i, origin, direction, 0.0f, tmax);
    rays.pixel[i] = id;
    rays.sample[i] = 0;
    rays.depth[i] = 0;
    rays.kind[i] = kind;
    rays.throughput_r[i] = rays.throughput_g[i] = rays.throughput_b[i] = 1.0f;
    rays.flags[i] = ray_flags::alive;
  }
};

// Camera rays over a 4:3 image of about `count` pixels, one sample per pixel, in 2x2
// pixel quads (scanline order of the quads), so any 4 aligned consecutive rays form a
// packet; round `round` jitters differently so repeated rounds give new rays.
void add_primary(RayWriter& writer, const Camera& camera, std::size_t count, std::uint32_t round) {
  const auto height = static_cast<std::uint32_t>(std::max(1.0, std::round(std::sqrt(double(count) * 0.75))));
  const auto width = static_cast<std::uint32_t>((count + height - 1) / height + 1) / 2 * 2;
  const CameraFrame frame(camera, float(width) / float(height));
  const std::uint32_t quads_per_row = width / 2;
  for (std::size_t p = 0; p < count; ++p) {
    const auto pixel = static_cast<std::uint32_t>(p);
    const std::uint32_t quad = pixel / 4, corner = pixel % 4;
    const std::uint32_t column = 2 * (quad % quads_per_row) + corner % 2, row = 2 * (quad / quads_per_row) + corner / 2;
    const UnitPair jitter = unit_pair(random_bits(pixel, round, 0, RandomPurpose::pixel_jitter));
    const float x = (float(column) + jitter.first) / float(width);
    const float y = 1.0f - (float(row) + jitter.second) / float(height);
    writer.add(frame.origin, glm::normalize(frame.direction(x, y)), kInfinity, RayKind::camera, pixel);
  }
}

struct SurfacePoint {
  glm::vec3 origin;  // offset off the surface toward the viewer
  glm::vec3 normal;  // facing the viewer
  std::uint32_t id;
};

// Primary hits as surface points, as many rounds of camera rays as it takes to find `count`.
std::vector<SurfacePoint> primary_surface_points(const Scene& scene, const Accelerator& reference, std::size_t count) {
  const Camera camera = resolve_camera(CameraOverride{}, scene);
  std::vector<SurfacePoint> points;
  for (std::uint32_t round = 0; points.size() < count && round < 64; ++round) {
    RaySet primary{RaySetKind::primary, {}};
    RayWriter writer{primary, kDefaultBatchCapacity};
    add_primary(writer, camera, count, round);
    const auto hits = trace_ray_set(reference, primary);
    for (std::size_t b = 0; b < primary.batches.size(); ++b) {
      const RayBatch& rays = *primary.batches[b];
      for (std::size_t i = 0; i < rays.count && points.size() < count; ++i) {
        if (!hits[b]->is_hit(i)) continue;
        // The hit's own surface (every accelerator records it for closest hits): no mesh needed,
        // so a saved world's ray sets are the ones its fresh build would get.
        const HitBatch& hit = *hits[b];
        const glm::vec3 point(hit.point_x[i], hit.point_y[i], hit.point_z[i]);
        const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
        glm::vec3 normal = glm::normalize(glm::vec3(hit.normal_x[i], hit.normal_y[i], hit.normal_z[i]));
        if (glm::dot(normal, direction) > 0.0f) normal = -normal;
        points.push_back({offset_ray_origin(point, normal), normal, static_cast<std::uint32_t>(points.size())});
      }
    }
    if (round == 0 && points.empty()) break;
  }
  if (points.empty()) throw std::runtime_error(scene.name + ": no camera ray hits the scene, so no diffuse or shadow rays");
  return points;
}

}  // namespace

RaySetKind parse_ray_set_kind(const std::string& text) {
  if (text == "primary") return RaySetKind::primary;
  if (text == "diffuse") return RaySetKind::diffuse;
  if (text == "shadow") return RaySetKind::shadow;
  if (text == "random") return RaySetKind::random;
  throw std::invalid_argument("unknown ray set '" + text + "' (primary, diffuse, shadow, random)");
}

std::string to_string(RaySetKind kind) {
  switch (kind) {
    case RaySetKind::diffuse: return "diffuse";
    case RaySetKind::shadow: return "shadow";
    case RaySetKind::random: return "random";
    default: return "primary";
  }
}

std::size_t RaySet::count() const {
  std::size_t total = 0;
  for (const auto& batch : batches) total += batch->count;
  return total;
}

RaySet make_ray_set(RaySetKind kind, const Scene& scene, const Accelerator& reference, std::size_t count,
                    std::size_t batch_size, const LightSampler* scene_lights) {
  RaySet set{kind, {}};
  RayWriter writer{set, batch_size};
  const Bounds3 bounds = scene.bounds;
  switch (kind) {
    case RaySetKind::primary: add_primary(writer, resolve_camera(CameraOverride{}, scene), count, 0); break;
    case RaySetKind::diffuse: {
      for (const SurfacePoint& p : primary_surface_points(scene, reference, count)) {
        const UnitPair u = unit_pair(random_bits(p.id, 0, 1, RandomPurpose::bounce_direction));
        writer.add(p.origin, cosine_hemisphere(p.normal, u.first, u.second), kInfinity, RayKind::bounce, p.id);
      }
      break;
    }
    case RaySetKind::shadow: {
      const std::optional<LightSampler> own_lights =
          scene_lights == nullptr ? std::optional<LightSampler>(std::in_place, scene) : std::nullopt;
      const LightSampler& lights = scene_lights != nullptr ? *scene_lights : *own_lights;
      // Without lights: a square light a half diagonal above the scene, facing down.
      const float size = 0.5f * bounds.diagonal();
      const glm::vec3 virtual_corner(bounds.center().x - 0.5f * size, bounds.upper.y + size, bounds.center().z - 0.5f * size);
      for (const SurfacePoint& p : primary_surface_points(scene, reference, count)) {
        const UnitPair u = unit_pair(random_bits(p.id, 0, 1, RandomPurpose::light_point));
        glm::vec3 target;
        if (lights.empty()) {
          target = virtual_corner + glm::vec3(u.first * size, 0.0f, u.second * size);
        } else {
          const float choice = unit_float(random_bits(p.id, 0, 1, RandomPurpose::light_choice));
          target = lights.sample(choice, u.first, u.second).point;
        }
        const glm::vec3 to_target = target - p.origin;
        const float distance = glm::length(to_target);
        if (!(distance > 0.0f)) continue;
        writer.add(p.origin, to_target / distance, distance * (1.0f - 1e-4f), RayKind::shadow, p.id);
      }
      break;
    }
    case RaySetKind::random: {
      const glm::vec3 center = bounds.center();
      const float radius = bounds.diagonal();
      for (std::size_t r = 0; r < count; ++r) {
        const auto id = static_cast<std::uint32_t>(r);
        const UnitPair on_sphere = unit_pair(random_bits(id, 0, 0, RandomPurpose::benchmark));
        const UnitPair inside = unit_pair(random_bits(id, 0, 1, RandomPurpose::benchmark));
        const float inside_z = unit_float(random_bits(id, 0, 2, RandomPurpose::benchmark));
        const glm::vec3 origin = center + radius * uniform_sphere(on_sphere.first, on_sphere.second);
        const glm::vec3 target = bounds.lower + bounds.extent() * glm::vec3(inside.first, inside.second, inside_z);
        writer.add(origin, glm::normalize(target - origin), kInfinity, RayKind::camera, id);
      }
      break;
    }
  }
  return set;
}

std::vector<std::unique_ptr<HitBatch>> make_hit_batches(const RaySet& rays) {
  std::vector<std::unique_ptr<HitBatch>> hits(rays.batches.size());
  tbb::parallel_for(std::size_t{0}, rays.batches.size(),
                    [&](std::size_t b) { hits[b] = std::make_unique<HitBatch>(rays.batches[b]->capacity()); });
  return hits;
}

void trace_ray_set(const Accelerator& accelerator, const RaySet& rays, std::vector<std::unique_ptr<HitBatch>>& hits,
                   bool coherent) {
  tbb::parallel_for(std::size_t{0}, rays.batches.size(), [&](std::size_t b) {
    if (rays.any_hit()) {
      accelerator.intersect_any(*rays.batches[b], *hits[b], rays.batches[b]->all());
    } else if (coherent && rays.kind == RaySetKind::primary) {
      accelerator.intersect_coherent(*rays.batches[b], *hits[b], rays.batches[b]->all());
    } else {
      accelerator.intersect_closest(*rays.batches[b], *hits[b], rays.batches[b]->all());
    }
  });
}

std::vector<std::unique_ptr<HitBatch>> trace_ray_set(const Accelerator& accelerator, const RaySet& rays,
                                                     bool coherent) {
  std::vector<std::unique_ptr<HitBatch>> hits = make_hit_batches(rays);
  trace_ray_set(accelerator, rays, hits, coherent);
  return hits;
}

}  // namespace wavetrace

namespace wavetrace {

std::vector<std::unique_ptr<HitBatch>> trace_ray_set_probed(const Accelerator& accelerator, const RaySet& rays,
                                                            const MemoryObservers& observers) {
  std::vector<std::unique_ptr<HitBatch>> hits(rays.batches.size());
  tbb::parallel_for(std::size_t{0}, rays.batches.size(), [&](std::size_t b) {
    hits[b] = std::make_unique<HitBatch>(rays.batches[b]->capacity());
    RecordingProbe probe(observers, 0, std::size_t(tbb::this_task_arena::current_thread_index()));
    if (rays.any_hit()) {
      accelerator.intersect_any_probed(*rays.batches[b], *hits[b], rays.batches[b]->all(), probe);
    } else {
      accelerator.intersect_closest_probed(*rays.batches[b], *hits[b], rays.batches[b]->all(), probe);
    }
  });
  return hits;
}

}  // namespace wavetrace
