// The watertight test (triangle_intersect.hpp) for several triangles at once, one per SIMD
// lane (4 with SSE, 8 with AVX2, 16 in the AVX-512 walks), with the scalar test's float operations in the scalar
// test's order, so every lane's edge weights, determinant and distance are bit-identical to
// intersect_watertight's. Lanes with an edge weight of exactly zero (where the scalar test
// redoes the edges in double) are reported apart for the caller to redo with the scalar test.
//
// Written once for every width with the vector extensions GCC and Clang share (`a * b` on
// __m256 is one vmulps), so the widths cannot drift apart; only loads, splats and the mask
// extraction name the width.
#pragma once

#include "wavetrace/build_config.hpp"

#include <cstddef>
#include <cstdint>

#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"

#if WAVETRACE_AVX2
#include <immintrin.h>
#endif

// Sixteen lanes, for the AVX-512 walks (WAVETRACE_SIXTEEN_LANES, kernel_isa.hpp): GCC compiles
// this file's shared code at 16 lanes where it is inlined into the one function of that target.

namespace wavetrace {

// Corners in SoA: corner[c][axis][lane]; unused lanes may hold anything finite or not.
template <int kLanes>
struct TriangleLanes {
  alignas(4 * kLanes) float corner[3][3][kLanes];
};

// Per lane, what the scalar test computes before its final tmax comparison (on t, which the
// caller makes against its tmax of the moment).
template <int kLanes>
struct WatertightLanes {
  alignas(4 * kLanes) float t[kLanes], u[kLanes], v[kLanes];
  unsigned candidates = 0;  // inside, det != 0, t * |det| in [tmin, tmax * slack] * |det|
  unsigned on_edge = 0;     // an edge weight is exactly zero in float: redo with intersect_watertight
};

#if WAVETRACE_AVX2

namespace lanes {

// Comparisons are named (equal, less, greater: false where either side is NaN, as C's
// operators are) so that each width gives them its own mask type: a vector of -1 and 0 for
// SSE and AVX2, a mask register for AVX-512, where GCC 12 turns a vector-extension compare
// of 16 floats into sixteen scalar ones.
template <int kLanes> struct Vector;
template <> struct Vector<4> {
  using Float = __m128;
  using Int = std::int32_t __attribute__((vector_size(16)));
  static Float splat(float x) { return _mm_set1_ps(x); }
  static Float load(const float* p) { return _mm_load_ps(p); }
  static void store(float* p, Float x) { _mm_store_ps(p, x); }
  static auto equal(Float a, Float b) { return a == b; }
  static auto less(Float a, Float b) { return a < b; }
  static auto greater(Float a, Float b) { return a > b; }
  template <typename Mask> static unsigned bits(Mask m) { return static_cast<unsigned>(_mm_movemask_ps(Float(m))); }
};
template <> struct Vector<8> {
  using Float = __m256;
  using Int = std::int32_t __attribute__((vector_size(32)));
  static Float splat(float x) { return _mm256_set1_ps(x); }
  static Float load(const float* p) { return _mm256_load_ps(p); }
  // Lanes 0-3 from `p`, lanes 4-7 from `p + stride` (two rows of four, e.g. two blocks').
  static Float load_fours(const float* p, std::ptrdiff_t stride) { return _mm256_loadu2_m128(p + stride, p); }
  static void store(float* p, Float x) { _mm256_store_ps(p, x); }
  static auto equal(Float a, Float b) { return a == b; }
  static auto less(Float a, Float b) { return a < b; }
  static auto greater(Float a, Float b) { return a > b; }
  template <typename Mask> static unsigned bits(Mask m) { return static_cast<unsigned>(_mm256_movemask_ps(Float(m))); }
};
#if WAVETRACE_SIXTEEN_LANES
// Only the AVX-512 walks instantiate it: members of that target, which only a function of that
// target may inline (kernel_isa.hpp).
template <> struct Vector<16> {
  using Float = __m512;
  using Int = std::int32_t __attribute__((vector_size(64)));
  [[WAVETRACE_AVX512_TARGET]] static Float splat(float x) { return _mm512_set1_ps(x); }
  [[WAVETRACE_AVX512_TARGET]] static Float load(const float* p) { return _mm512_load_ps(p); }
  [[WAVETRACE_AVX512_TARGET]] static void store(float* p, Float x) { _mm512_store_ps(p, x); }
  [[WAVETRACE_AVX512_TARGET]] static __mmask16 equal(Float a, Float b) { return _mm512_cmp_ps_mask(a, b, _CMP_EQ_OQ); }
  [[WAVETRACE_AVX512_TARGET]] static __mmask16 less(Float a, Float b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
  [[WAVETRACE_AVX512_TARGET]] static __mmask16 greater(Float a, Float b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
  static unsigned bits(unsigned m) { return m & 0xffffu; }
};
#endif

}  // namespace lanes

#if WAVETRACE_SIXTEEN_LANES
// GCC warns that the 16-lane instance calls functions that return __m512 from a function not
// of the AVX-512 target; it runs only inlined into one (kernel_isa.hpp), so no call is made.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
// Tests the kLanes triangles of `lanes` from lane `first` on (a multiple of kLanes). Rows of
// four lanes narrower than the test (eight lanes over two blocks of four) are read from
// `lanes` and from the rows `row_stride` floats after it, which must hold a whole block too.
template <int kLanes, int kRowLanes>
[[gnu::always_inline]] inline void intersect_watertight_lanes(const WatertightRay& ray, const TriangleLanes<kRowLanes>& lanes,
                                                              unsigned used, float tmin, float tmax,
                                                              WatertightLanes<kLanes>& out, int first = 0,
                                                              std::ptrdiff_t row_stride = 0) {
  using V = lanes::Vector<kLanes>;
  using Float = typename V::Float;
  const int axes[3] = {ray.kx, ray.ky, ray.kz};
  // An array, not glm's operator[], which compiles to a switch per use.
  const float ray_origin[3] = {ray.origin.x, ray.origin.y, ray.origin.z};
  Float origin[3];
  for (int k = 0; k < 3; ++k) origin[k] = V::splat(ray_origin[axes[k]]);
  Float relative[3][3];  // corner, permuted axis (x, y, z of the sheared frame before shearing)
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) {
      const float* row = lanes.corner[c][axes[k]] + first;
      if constexpr (kRowLanes == 4 && kLanes == 8) {
        relative[c][k] = V::load_fours(row, row_stride) - origin[k];
      } else {
        static_assert(kRowLanes >= kLanes, "rows narrower than the test are read in fours, eight lanes from two");
        relative[c][k] = V::load(row) - origin[k];
      }
    }
  }
  const Float shear_x = V::splat(ray.shear_x), shear_y = V::splat(ray.shear_y);
  Float px[3], py[3];
  for (int c = 0; c < 3; ++c) {
    px[c] = relative[c][0] - shear_x * relative[c][2];
    py[c] = relative[c][1] - shear_y * relative[c][2];
  }
  // a = corner 0, b = corner 1, c = corner 2, as in the scalar test.
  const Float u = px[2] * py[1] - py[2] * px[1];
  const Float v = px[0] * py[2] - py[0] * px[2];
  const Float w = px[1] * py[0] - py[1] * px[0];
  const Float zero = V::splat(0.0f);
  const auto on_edge = V::equal(u, zero) | V::equal(v, zero) | V::equal(w, zero);
  const auto any_negative = V::less(u, zero) | V::less(v, zero) | V::less(w, zero);
  const auto any_positive = V::greater(u, zero) | V::greater(v, zero) | V::greater(w, zero);
  const Float determinant = (u + v) + w;
  const Float shear_z = V::splat(ray.shear_z);
  const Float scaled_t = (u * (shear_z * relative[0][2]) + v * (shear_z * relative[1][2])) + w * (shear_z * relative[2][2]);
  // |det| and t * sign(det) by the sign bit, which is what fabs and the multiplication by
  // copysign(1, det) do to every value the comparisons below can tell apart.
  using Int = typename V::Int;
  const Int sign_bit = Int(determinant) & static_cast<int>(0x80000000u);
  const Float abs_determinant = Float(Int(determinant) ^ sign_bit);
  const Float signed_t = Float(Int(scaled_t) ^ sign_bit);
  // The scalar test rejects on `<` or `>`; a NaN compares false there and passes, so here too.
  const auto outside_interval =
      V::less(signed_t, V::splat(tmin) * abs_determinant) |
      V::greater(signed_t, (V::splat(tmax) * abs_determinant) * V::splat(kDistancePrecheckSlack));
  const auto rejected = (any_negative & any_positive) | outside_interval | V::equal(determinant, zero);
  const Float inverse = V::splat(1.0f) / determinant;
  V::store(out.t, scaled_t * inverse);
  V::store(out.u, v * inverse);
  V::store(out.v, w * inverse);
  out.on_edge = V::bits(on_edge) & used;
  out.candidates = ~V::bits(rejected) & used & ~out.on_edge;
}
#if WAVETRACE_SIXTEEN_LANES
#pragma GCC diagnostic pop
#endif

#endif  // WAVETRACE_AVX2

}  // namespace wavetrace
