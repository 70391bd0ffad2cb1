// Box clip, retirement of box misses (with compaction), proxy query, approximate points.
#include "wavetrace/stages/approx_hit.hpp"

#include <algorithm>
#include <optional>

#include <tbb/task_arena.h>

#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/stages/escaped_light.hpp"
#include "wavetrace/stages/observed_stage.hpp"

namespace wavetrace {

ApproxHitStage::ApproxHitStage(const Proxy& proxy, Film* film, const glm::vec3& background, HitRateCounters* hit_rates,
                               const MemoryObservers* observers)
    : proxy_(proxy),
      film_(film),
      background_(background),
      hit_rates_(hit_rates),
      observers_(observers != nullptr && observers->any() && proxy.accelerator().probed() ? observers : nullptr) {}

void ApproxHitStage::process(Batch* batch, StageOutput& out) const {
  RayBatch& rays = batch->rays;
  rays.enable_approx_hit();
  const Bounds3& box = proxy_.scene_bounds();
  // Rays inside the box keep their slot; others are finished here. Survivors move down in
  // order, keeping where each survivor enters and leaves the box for its virtual hit.
  std::vector<float> box_near(rays.count), box_far(rays.count);
  std::array<std::uint32_t, HitRateCounters::kDepths> missed_by_depth{};
  bool any_missed = false;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < rays.count; ++i) {
    const glm::vec3 origin(rays.origin_x[i], rays.origin_y[i], rays.origin_z[i]);
    const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
    float near = 0.0f, far = 0.0f;
    if (!clip_to_box(make_box_ray(origin, direction), box.lower, box.upper, rays.tmin[i], rays.tmax[i], near, far)) {
      if (film_ != nullptr) add_escaped_ray_light(*film_, rays, i, background_);
      if (rays.kind[i] != RayKind::shadow) {
        ++missed_by_depth[std::min<std::size_t>(rays.depth[i], HitRateCounters::kDepths - 1)];
        any_missed = true;
      }
      continue;
    }
    if (kept != i) rays.copy_ray(kept, rays, i);
    box_near[kept] = near;
    box_far[kept] = far;
    ++kept;
  }
  if (any_missed && hit_rates_ != nullptr) {
    for (int depth = 0; depth < HitRateCounters::kDepths; ++depth) {
      if (missed_by_depth[depth] > 0) hit_rates_->add(depth, missed_by_depth[depth], 0);
    }
  }
  rays.count = kept;
  if (kept == 0) {
    out.release(batch);
    return;
  }

  // The proxy's closest hits' distances, into the hit columns trace will overwrite, from one
  // surface tolerance past each origin (restored after).
  HitBatch& hits = batch->hits;
  std::vector<float> tmin(rays.tmin, rays.tmin + kept);
  for (std::size_t i = 0; i < kept; ++i) rays.tmin[i] += proxy_.surface_tolerance();
  if (observers_ != nullptr) {
    RecordingProbe probe(*observers_, std::size_t(ObservedStage::approx_hit),
                         std::size_t(tbb::this_task_arena::current_thread_index()));
    proxy_.accelerator().intersect_closest_probed(rays, hits, rays.all(), probe);
  } else {
    proxy_.accelerator().intersect_distance(rays, hits, rays.all());  // only t is read below
  }
  std::copy(tmin.begin(), tmin.end(), rays.tmin);
  for (std::size_t i = 0; i < kept; ++i) {
    // A virtual hit: where the ray enters the box, or leaves it when it starts inside. A
    // shadow ray that meets no proxy surface before its light has no hit at all; its
    // traversal works hardest where it starts, so its origin stands for it.
    float t = hits.is_hit(i) ? hits.t[i] : (box_near[i] > rays.tmin[i] ? box_near[i] : box_far[i]);
    if (!hits.is_hit(i) && rays.kind[i] == RayKind::shadow) t = rays.tmin[i];
    if (!std::isfinite(t)) t = box_near[i];
    rays.approx_hit_x[i] = rays.origin_x[i] + t * rays.direction_x[i];
    rays.approx_hit_y[i] = rays.origin_y[i] + t * rays.direction_y[i];
    rays.approx_hit_z[i] = rays.origin_z[i] + t * rays.direction_z[i];
  }
  out.emit(batch);
}

}  // namespace wavetrace
