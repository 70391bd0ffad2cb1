// Gathering rays are written first, clearing their parents' `continues`, so that the path
// tracer's spawn, run after on the same batch, adds only light samples and the camera paths'
// specular bounces.
#include "wavetrace/stages/gather_spawn.hpp"

#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {
namespace {

// Batches filled one ray at a time, each emitted when full (and the last at finish).
class BatchFiller {
 public:
  explicit BatchFiller(StageOutput& out) : out_(out) {}
  RayBatch& room_for_one() {
    if (open_ != nullptr && open_->rays.count == open_->rays.capacity()) {
      out_.emit(open_);
      open_ = nullptr;
    }
    if (open_ == nullptr) open_ = out_.acquire();
    return open_->rays;
  }
  void finish() {
    if (open_ == nullptr) return;
    if (open_->rays.count == 0) {
      out_.release(open_);
    } else {
      out_.emit(open_);
    }
    open_ = nullptr;
  }

 private:
  StageOutput& out_;
  Batch* open_ = nullptr;
};

}  // namespace

GatherSpawnStage::GatherSpawnStage(const World& world, const PathRules& rules, std::uint32_t gather_rays)
    : world_(world), rules_(rules), gather_rays_(gather_rays), path_(world, rules) {
  if (gather_rays == 0 || gather_rays > kMaxGatherRays) {
    throw std::invalid_argument("photon.gather_rays must be in [1, 128]");
  }
}

void GatherSpawnStage::process(Batch* batch, StageOutput& out) const {
  RayBatch& rays = batch->rays;
  const HitBatch& hits = batch->hits;
  BatchFiller gathered(out);
  const float share = 1.0f / float(gather_rays_);
  for (std::size_t i = 0; i < rays.count; ++i) {
    if ((rays.flags[i] & (ray_flags::alive | ray_flags::continues)) != (ray_flags::alive | ray_flags::continues)) {
      continue;
    }
    const Material& material = world_.scene.materials[hits.material[i]];
    if (material.specular()) {
      if (rays.kind[i] == RayKind::bounce) {  // a gathering ray goes on through the glass
        write_specular_bounce(rays, hits, i, material, rules_, gathered.room_for_one(), RayKind::bounce);
        rays.flags[i] = ray_flags::alive;
      }
      continue;  // a camera path's: the path tracer's spawn bounces it
    }
    const std::uint32_t depth = rays.depth[i];
    const std::uint64_t key = path_key(rays.pixel[i], rays.sample[i]);
    const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
    const glm::vec3 normal = glm::normalize(hits.normal(i));
    const glm::vec3 facing = glm::dot(normal, direction) > 0.0f ? -normal : normal;
    const glm::vec3 origin = offset_ray_origin(hits.point(i), facing);
    const glm::vec3 weight =
        glm::vec3(rays.throughput_r[i], rays.throughput_g[i], rays.throughput_b[i]) * material.albedo * share;
    for (std::uint32_t j = 0; j < gather_rays_; ++j) {
      const glm::vec3 bounce =
          cosine_hemisphere(facing, unit_float32(path_draw(key, depth, RandomPurpose::gather_direction, 2 * j)),
                            unit_float32(path_draw(key, depth, RandomPurpose::gather_direction, 2 * j + 1)));
      RayBatch& to = gathered.room_for_one();
      const std::size_t slot = to.count++;
      to.set_geometry(slot, origin, bounce, 0.0f, std::numeric_limits<float>::infinity());
      to.pixel[slot] = rays.pixel[i];
      // A sample number of its own keys the ray's later draws (a glass's Fresnel choice)
      // apart from its siblings'; the film reads only the pixel.
      to.sample[slot] = path_draw(key, depth, RandomPurpose::gather_key, j);
      to.depth[slot] = static_cast<std::uint16_t>(depth + 1);
      to.kind[slot] = RayKind::bounce;
      to.throughput_r[slot] = weight.r;
      to.throughput_g[slot] = weight.g;
      to.throughput_b[slot] = weight.b;
      to.flags[slot] = ray_flags::alive;
    }
    rays.flags[i] = ray_flags::alive;  // the light sample is left to the path tracer's spawn
  }
  gathered.finish();
  path_.process(batch, out);
}

}  // namespace wavetrace
