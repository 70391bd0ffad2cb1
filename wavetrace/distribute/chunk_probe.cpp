// Camera rays of a coarse image and one bounce from their hits, counted chunk by chunk.
#include "wavetrace/distribute/chunk_probe.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

std::vector<std::uint64_t> probe_rays_due(const ChunkSet& chunks, const Camera& camera, float aspect,
                                          std::uint32_t width, const std::function<void()>& after_batch) {
  constexpr float kInfinity = std::numeric_limits<float>::infinity();
  const auto height = static_cast<std::uint32_t>(std::max(1.0f, std::round(float(width) / aspect)));
  const CameraFrame frame(camera, float(width) / float(height));
  const std::size_t pixels = std::size_t{width} * height;
  std::vector<std::uint64_t> rays_due(chunks.chunk_count(), 0);
  Batch camera_rays(kProbeBatchRays), bounces(kProbeBatchRays);
  for (std::size_t first = 0; first < pixels; first += kProbeBatchRays) {
    RayBatch& rays = camera_rays.rays;
    rays.count = std::min(kProbeBatchRays, pixels - first);
    for (std::size_t i = 0; i < rays.count; ++i) {
      const auto pixel = static_cast<std::uint32_t>(first + i);
      const std::uint32_t row = pixel / width, column = pixel % width;
      const float x = (float(column) + 0.5f) / float(width), y = 1.0f - (float(row) + 0.5f) / float(height);
      rays.set_geometry(i, frame.origin, glm::normalize(frame.direction(x, y)), 0.0f, kInfinity);
      rays.kind[i] = RayKind::camera;
      rays.flags[i] = ray_flags::alive;
    }
    chunks.count_rays_due(rays, camera_rays.hits, rays_due);

    std::size_t count = 0;
    for (std::size_t i = 0; i < rays.count; ++i) {
      if (!camera_rays.hits.is_hit(i)) continue;
      const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
      glm::vec3 normal = camera_rays.hits.normal(i);
      if (glm::dot(normal, direction) > 0.0f) normal = -normal;  // the side the camera sees
      const UnitPair u =
          unit_pair(random_bits(static_cast<std::uint32_t>(first + i), 0, 1, RandomPurpose::chunk_probe));
      bounces.rays.set_geometry(count, offset_ray_origin(camera_rays.hits.point(i), normal),
                                cosine_hemisphere(normal, u.first, u.second), 0.0f, kInfinity);
      bounces.rays.kind[count] = RayKind::bounce;
      bounces.rays.flags[count] = ray_flags::alive;
      ++count;
    }
    bounces.rays.count = count;
    if (count > 0) chunks.count_rays_due(bounces.rays, bounces.hits, rays_due);
    if (after_batch) after_batch();
  }
  return rays_due;
}

}  // namespace wavetrace
