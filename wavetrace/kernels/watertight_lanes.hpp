// The watertight test (triangle_intersect.hpp) for up to eight triangles at once, one per
// AVX2 lane, with the scalar test's float operations in the scalar test's order, so every
// lane's edge weights, determinant and distance are bit-identical to intersect_watertight's.
// Lanes with an edge weight of exactly zero (where the scalar test redoes the edges in
// double) are reported apart for the caller to redo with the scalar test.
#pragma once

#include "wavetrace/build_config.hpp"

#if WAVETRACE_AVX2

#include <cstdint>

#include <immintrin.h>

#include "wavetrace/kernels/triangle_intersect.hpp"

namespace wavetrace {

// Corners in SoA: corner[c][axis][lane]; unused lanes may hold anything finite or not.
struct TriangleLanes {
  alignas(32) float corner[3][3][8];
};

// Per lane, what the scalar test computes before its final tmax comparison (on t, which the
// caller makes against its tmax of the moment).
struct WatertightLanes {
  alignas(32) float t[8], u[8], v[8];
  unsigned candidates = 0;  // inside, det != 0, t * |det| in [tmin, tmax * slack] * |det|
  unsigned on_edge = 0;     // an edge weight is exactly zero in float: redo with intersect_watertight
};

[[gnu::always_inline]] inline void intersect_watertight_lanes(const WatertightRay& ray, const TriangleLanes& lanes,
                                                              unsigned used, float tmin, float tmax,
                                                              WatertightLanes& out) {
  const int axes[3] = {ray.kx, ray.ky, ray.kz};
  __m256 relative[3][3];  // corner, permuted axis (x, y, z of the sheared frame before shearing)
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) {
      relative[c][k] = _mm256_sub_ps(_mm256_load_ps(lanes.corner[c][axes[k]]), _mm256_set1_ps(ray.origin[axes[k]]));
    }
  }
  const __m256 shear_x = _mm256_set1_ps(ray.shear_x), shear_y = _mm256_set1_ps(ray.shear_y);
  __m256 px[3], py[3];
  for (int c = 0; c < 3; ++c) {
    px[c] = _mm256_sub_ps(relative[c][0], _mm256_mul_ps(shear_x, relative[c][2]));
    py[c] = _mm256_sub_ps(relative[c][1], _mm256_mul_ps(shear_y, relative[c][2]));
  }
  // a = corner 0, b = corner 1, c = corner 2, as in the scalar test.
  const __m256 u = _mm256_sub_ps(_mm256_mul_ps(px[2], py[1]), _mm256_mul_ps(py[2], px[1]));
  const __m256 v = _mm256_sub_ps(_mm256_mul_ps(px[0], py[2]), _mm256_mul_ps(py[0], px[2]));
  const __m256 w = _mm256_sub_ps(_mm256_mul_ps(px[1], py[0]), _mm256_mul_ps(py[1], px[0]));
  const __m256 zero = _mm256_setzero_ps();
  const __m256 on_edge = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_EQ_OQ), _mm256_cmp_ps(v, zero, _CMP_EQ_OQ)),
                                      _mm256_cmp_ps(w, zero, _CMP_EQ_OQ));
  const __m256 any_negative = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_LT_OQ), _mm256_cmp_ps(v, zero, _CMP_LT_OQ)),
                                           _mm256_cmp_ps(w, zero, _CMP_LT_OQ));
  const __m256 any_positive = _mm256_or_ps(_mm256_or_ps(_mm256_cmp_ps(u, zero, _CMP_GT_OQ), _mm256_cmp_ps(v, zero, _CMP_GT_OQ)),
                                           _mm256_cmp_ps(w, zero, _CMP_GT_OQ));
  const __m256 determinant = _mm256_add_ps(_mm256_add_ps(u, v), w);
  const __m256 shear_z = _mm256_set1_ps(ray.shear_z);
  const __m256 scaled_t = _mm256_add_ps(
      _mm256_add_ps(_mm256_mul_ps(u, _mm256_mul_ps(shear_z, relative[0][2])), _mm256_mul_ps(v, _mm256_mul_ps(shear_z, relative[1][2]))),
      _mm256_mul_ps(w, _mm256_mul_ps(shear_z, relative[2][2])));
  const __m256 sign_bit = _mm256_set1_ps(-0.0f);
  const __m256 sign = _mm256_or_ps(_mm256_and_ps(determinant, sign_bit), _mm256_set1_ps(1.0f));
  const __m256 abs_determinant = _mm256_andnot_ps(sign_bit, determinant);
  const __m256 signed_t = _mm256_mul_ps(scaled_t, sign);
  // The scalar test rejects on `<` or `>`; a NaN compares false there and passes, so here too.
  const __m256 outside_interval =
      _mm256_or_ps(_mm256_cmp_ps(signed_t, _mm256_mul_ps(_mm256_set1_ps(tmin), abs_determinant), _CMP_LT_OQ),
                   _mm256_cmp_ps(signed_t,
                                 _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(tmax), abs_determinant),
                                               _mm256_set1_ps(kDistancePrecheckSlack)),
                                 _CMP_GT_OQ));
  const __m256 rejected = _mm256_or_ps(_mm256_or_ps(_mm256_and_ps(any_negative, any_positive), outside_interval),
                                       _mm256_cmp_ps(determinant, zero, _CMP_EQ_OQ));
  const __m256 inverse = _mm256_div_ps(_mm256_set1_ps(1.0f), determinant);
  _mm256_store_ps(out.t, _mm256_mul_ps(scaled_t, inverse));
  _mm256_store_ps(out.u, _mm256_mul_ps(v, inverse));
  _mm256_store_ps(out.v, _mm256_mul_ps(w, inverse));
  out.on_edge = static_cast<unsigned>(_mm256_movemask_ps(on_edge)) & used;
  out.candidates = ~static_cast<unsigned>(_mm256_movemask_ps(rejected)) & used & ~out.on_edge;
}

}  // namespace wavetrace

#endif
