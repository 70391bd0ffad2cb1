// Test helper: how an accelerator's answers on one ray set compare with a reference's —
// hits, hit distances and barycentrics.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/scene.hpp"

namespace wavetrace::testing {

struct Agreement {
  std::size_t rays = 0;
  std::size_t hit_differs = 0;     // one hits, the other does not
  std::size_t far_t = 0;           // both hit, t further apart than the tolerance
  std::size_t far_uv = 0;          // same triangle, barycentrics further apart than the tolerance
  std::size_t same_primitive = 0;  // both hit the same triangle
};

// Rays of `kind` made with the reference; with `packets`, primary rays go through
// intersect_coherent.
inline Agreement compare_on_rays(const Scene& scene, const Accelerator& reference, const Accelerator& tested,
                                 RaySetKind kind, std::size_t count, float t_tolerance, float uv_tolerance,
                                 bool packets = false) {
  const RaySet rays = make_ray_set(kind, scene, reference, count);
  const auto expected = trace_ray_set(reference, rays);
  const auto actual = trace_ray_set(tested, rays, packets);
  Agreement result;
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
      ++result.rays;
      const HitBatch& e = *expected[b];
      const HitBatch& a = *actual[b];
      result.hit_differs += e.is_hit(i) != a.is_hit(i);
      if (rays.any_hit() || !e.is_hit(i) || !a.is_hit(i)) continue;
      result.far_t += std::fabs(e.t[i] - a.t[i]) > t_tolerance;
      if (e.primitive[i] == a.primitive[i]) {
        ++result.same_primitive;
        result.far_uv += std::fabs(e.u[i] - a.u[i]) > uv_tolerance || std::fabs(e.v[i] - a.v[i]) > uv_tolerance;
      }
    }
  }
  return result;
}

// The scenes each accelerator is checked on against Embree: a closed mesh, one without
// connectivity, a height field, thin axis-aligned geometry and a scanned mesh.
inline std::vector<std::string> agreement_scenes(const std::string& soup) {
  return {"builtin:sphere:100k", soup, "builtin:terrain:50k", "builtin:stadium:2000",
          std::string(WAVETRACE_DATA_DIR) + "/bunny00.off"};
}

inline std::string agreement_scene_label(const ::testing::TestParamInfo<std::string>& info) {
  static const std::vector<std::string> names = {"sphere", "soup", "terrain", "stadium", "bunny"};
  return names[info.index];
}

}  // namespace wavetrace::testing
