// One ray through one Ray-Strip (§5.1, Algorithm 1): the implicit kd-tree walked near
// child first with the ray's [dmin, dmax] interval and the strip interval tracked on a
// small stack, and the shared-edge intersection of a run of strip triangles (§5.2).
//
// Edge tests. Each vertex of the run is moved into the watertight test's ray space (origin
// at the ray origin, sheared so the ray runs along +z; Woop et al. 2013), where the Plücker
// side of the ray against an edge (p, q) is the 2D edge function f(p, q) = q.x p.y - q.y p.x.
// A run of m triangles has m + 2 vertices and 2m + 1 edges: the strip edges (s[j], s[j+1])
// and the diagonals (s[j], s[j+2]); triangle j uses f(s[j+1], s[j+2]), -f(s[j], s[j+2]) and
// f(s[j], s[j+1]) as the weights of its corners, and is hit when the three signs agree. The
// arithmetic is the watertight test's (an exact zero is redone in double), and f(q, p) is
// exactly -f(p, q), so two triangles sharing an edge — in a strip or across strips — see
// the same edge value and no ray slips between them. Runs are processed 6 triangles
// (8 vertices, 7 + 6 edges) at a time in 8-lane vectors (AVX2); in the AVX-512 walks a top
// leaf's short strips are packed back to back into sixteen lanes and tested at once.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <glm/vec3.hpp>

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2
#if WAVETRACE_AVX2
#include <immintrin.h>
#endif

#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/accel/raystrips/ray_strip_format.hpp"
#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"

namespace wavetrace {

// Slack on the kd-tree's plane distances: the float error of (plane - origin) * inverse.
inline constexpr float kPlaneDistanceSlack = 2.0f * float_error_gamma(2);

// A plane distance moved outward by that error bound: later (exit) or earlier (entry).
inline float widen_exit(float t) { return t * (t > 0.0f ? 1.0f + kPlaneDistanceSlack : 1.0f - kPlaneDistanceSlack); }
inline float widen_entry(float t) { return t * (t > 0.0f ? 1.0f - kPlaneDistanceSlack : 1.0f + kPlaneDistanceSlack); }

inline constexpr std::uint32_t kRunVertices = 8;
inline constexpr std::uint32_t kRunTriangles = kRunVertices - 2;

// Whether a walk goes below the kd-node over leaves [first, first + leaves) of a strip of
// `triangles`: while its span holds more triangles than one run tests, where there is a tree.
inline bool descends(std::uint32_t triangles, std::uint32_t first, std::uint32_t leaves, std::uint32_t run_triangles) {
  return ray_strip::has_tree(triangles) && leaves >= 2 && std::min(2 * (first + leaves), triangles) - 2 * first > run_triangles;
}

#if WAVETRACE_SIXTEEN_LANES
// Short strips of one top leaf (no kd-tree: at most 14 triangles, 16 vertices), whole and back
// to back in sixteen lanes, for one shared-edge test of all of them (StripRay::test_packed):
// lane j holds one vertex, and is a triangle where j, j + 1 and j + 2 are one strip's. Most
// leaves under the 8-wide top hold one or two such strips. A strip's indices are widened into
// its lanes by one masked load, with no loop over them whose exit would be mispredicted.
struct PackedStrips {
  static constexpr std::uint32_t kLanes = 16;
  alignas(64) std::uint32_t vertex[kLanes];  // mesh vertex of each used lane
  const std::byte* strip_at[kLanes];         // the strip whose first vertex is in lane j
  std::uint32_t lanes = 0;
  unsigned starts = 0;       // bit j: a strip starts in lane j
  unsigned triangles = 0;    // bit j: lanes j, j + 1, j + 2 are a triangle of one strip
  unsigned strip_edges = 0;  // bit j: lanes j, j + 1 are an edge of one strip

  bool empty() const { return lanes == 0; }
  bool fits(std::uint32_t strip_triangles) const { return lanes + strip_triangles + 2 <= kLanes; }
  void clear() { lanes = starts = triangles = strip_edges = 0; }

  // The first lane of the strip that lane j belongs to.
  std::uint32_t first_lane(unsigned j) const {
    return 31u - static_cast<std::uint32_t>(std::countl_zero(starts & ((2u << j) - 1)));
  }

  // `view` has no kd-tree and fits.
  [[WAVETRACE_AVX512_TARGET]] void add(const ray_strip::StripView& view) {
    const std::uint32_t n = view.triangles();
    const __mmask16 used = static_cast<__mmask16>((1u << (n + 2)) - 1);
    const void* indices = view.vertex_address(0);
    __m512i stored;
    switch (view.index_width()) {
      case 1:
        stored = _mm512_maskz_cvtepu8_epi32(used, _mm_maskz_loadu_epi8(used, indices));
        break;
      case 2:
        stored = _mm512_maskz_cvtepu16_epi32(used, _mm256_maskz_loadu_epi16(used, indices));
        break;
      default:
        stored = _mm512_maskz_loadu_epi32(used, indices);
    }
    const __m512i base = _mm512_set1_epi32(static_cast<int>(view.vertex_base()));
    _mm512_mask_storeu_epi32(vertex + lanes, used, _mm512_add_epi32(stored, base));
    strip_at[lanes] = view.data();
    starts |= 1u << lanes;
    triangles |= ((1u << n) - 1) << lanes;
    strip_edges |= ((2u << n) - 1) << lanes;
    lanes += n + 2;
  }
};
static_assert(ray_strip::kUntreedTriangles + 2 == PackedStrips::kLanes, "a strip without a tree fits one pack alone");
#endif

// The nearest hit so far of one ray, in strip terms until it is written out.
struct StripHit {
  float t = std::numeric_limits<float>::infinity();
  float weights[3] = {0.0f, 0.0f, 0.0f};  // of the strip corners, normalized
  const std::byte* strip = nullptr;       // null: no hit
  std::uint32_t triangle = 0;             // strip triangle
};

class StripRay {
 public:
  explicit StripRay(const SingleRay& ray)
      : tmin(ray.tmin), tmax(ray.tmax), box(ray.box), sheared_(ray.sheared),
        origin_{ray.sheared.origin[ray.sheared.kx], ray.sheared.origin[ray.sheared.ky], ray.sheared.origin[ray.sheared.kz]} {}

  float tmin;
  float tmax;  // shrinks to the nearest hit found
  BoxRay box;
  StripHit hit;

  bool found() const { return hit.strip != nullptr; }

  // Walks the strip's kd-tree inside [dmin, dmax] (the part of the ray in the strip's frame,
  // the box of its top leaf), testing runs of at most `run_triangles` triangles. With kAnyHit
  // stops at the first hit.
  template <bool kAnyHit, typename Probe>
  void traverse(const ray_strip::StripView& strip, const Bounds3& frame, const glm::vec3* positions, float dmin,
                float dmax, std::uint32_t run_triangles, Probe& probe) {
    if (!ray_strip::has_tree(strip.triangles())) return test_run<kAnyHit>(strip, positions, 0, strip.triangles(), probe);
    traverse_subtree<kAnyHit>(strip, frame, positions, 0, 0, ray_strip::leaf_count(strip.triangles()), dmin, dmax,
                              run_triangles, probe);
  }

  // The same from kd-node `node` spanning leaves [first, first + leaves).
  template <bool kAnyHit, typename Probe>
  void traverse_subtree(const ray_strip::StripView& strip, const Bounds3& frame, const glm::vec3* positions,
                        std::uint32_t node,
                        std::uint32_t first, std::uint32_t leaves, float dmin, float dmax, std::uint32_t run_triangles,
                        Probe& probe) {
    using namespace ray_strip;
    struct Pending {
      std::uint32_t node, first, leaves;
      float dmin, dmax;
    };
    Pending stack[18];  // 65535 triangles: 16 levels of nodes
    std::uint32_t top = 0;
    const std::uint32_t triangles = strip.triangles();
    dmax = std::min(dmax, pruning_distance(tmax));
    while (true) {
      // Descend while the span holds more triangles than one run tests.
      while (descends(triangles, first, leaves, run_triangles)) {
        probe.read(strip.split_steps(node), 2);
        probe.read(strip.data() + strip.layout().node_bits + node, 1);
        const std::uint8_t bits = strip.node_bits(node);
        const int axis = bits & kAxisMask;
        const SplitPlanes planes = decode_split(strip.split_steps(node), frame, axis);
        const float split[2] = {planes.lower_child_max, planes.upper_child_min};
        const bool reverse = (bits & kReverse) != 0;
        const std::uint32_t first_leaves = (leaves + 1) / 2;
        const Pending strip_first{node + 1, first, first_leaves, 0, 0};
        const Pending strip_second{node + first_leaves, first + first_leaves, leaves - first_leaves, 0, 0};
        const Pending& lower = reverse ? strip_second : strip_first;
        const Pending& upper = reverse ? strip_first : strip_second;
        const float inverse = box.inverse_direction[axis];
        const bool positive = !std::signbit(inverse);
        const Pending& near = positive ? lower : upper;
        const Pending& far = positive ? upper : lower;
        const float near_exit = widen_exit(((positive ? split[0] : split[1]) - box.origin[axis]) * inverse);
        const float far_entry = widen_entry(((positive ? split[1] : split[0]) - box.origin[axis]) * inverse);
        // NaN (a ray in the plane) compares false both ways: both children stay in.
        const bool near_hit = !(near_exit < dmin);
        const bool far_hit = !(far_entry > dmax);
        if (near_hit) {
          if (far_hit) stack[top++] = {far.node, far.first, far.leaves, far_entry > dmin ? far_entry : dmin, dmax};
          node = near.node, first = near.first, leaves = near.leaves;
          dmax = near_exit < dmax ? near_exit : dmax;
        } else if (far_hit) {
          node = far.node, first = far.first, leaves = far.leaves;
          dmin = far_entry > dmin ? far_entry : dmin;
        } else {
          goto pop;
        }
      }
      test_run<kAnyHit>(strip, positions, 2 * first, std::min(2 * (first + leaves), triangles), probe);
      if (kAnyHit && found()) return;
    pop:
      while (top > 0 && stack[top - 1].dmin > pruning_distance(tmax)) --top;
      if (top == 0) return;
      --top;
      node = stack[top].node, first = stack[top].first, leaves = stack[top].leaves;
      dmin = stack[top].dmin;
      dmax = std::min(stack[top].dmax, pruning_distance(tmax));
    }
  }

#if WAVETRACE_SIXTEEN_LANES
  // The packed strips' triangles by shared edges in sixteen lanes: test_chunk's operations in
  // its order, lane for lane, so each triangle's weights and distance are the eight-lane
  // test's to the bit (and the nearest hit the same: ties go by triangle id).
  template <bool kAnyHit>
  [[WAVETRACE_AVX512_TARGET]] void test_packed(const PackedStrips& pack, const glm::vec3* positions) {
    // Each vertex read whole and the sixteen transposed into lanes, as test_chunk does;
    // lanes past the pack repeat its last vertex. (The masked forms of the shuffles start
    // from zero where the plain ones start from _mm512_undefined, which GCC 12 reports as
    // maybe uninitialized once inlined.)
    const std::uint32_t last = pack.lanes - 1;
    __m128 vertex[PackedStrips::kLanes];
    for (std::uint32_t i = 0; i < PackedStrips::kLanes; ++i) {
      vertex[i] = _mm_maskz_loadu_ps(0x7, &positions[pack.vertex[std::min(i, last)]].x);
    }
    __m512 row[4];  // row r: vertices r, r + 4, r + 8, r + 12 in its four 128-bit parts
    for (int r = 0; r < 4; ++r) {
      row[r] = _mm512_insertf32x4(_mm512_insertf32x4(_mm512_insertf32x4(_mm512_zextps128_ps512(vertex[r]),
                                                                        vertex[r + 4], 1),
                                                     vertex[r + 8], 2),
                                  vertex[r + 12], 3);
    }
    const __m512 xy01 = _mm512_maskz_unpacklo_ps(0xffff, row[0], row[1]);
    const __m512 xy23 = _mm512_maskz_unpacklo_ps(0xffff, row[2], row[3]);
    const __m512 z01 = _mm512_maskz_unpackhi_ps(0xffff, row[0], row[1]);
    const __m512 z23 = _mm512_maskz_unpackhi_ps(0xffff, row[2], row[3]);
    const __m512 axis[3] = {_mm512_shuffle_ps(xy01, xy23, 0x44), _mm512_shuffle_ps(xy01, xy23, 0xee),
                            _mm512_shuffle_ps(z01, z23, 0x44)};
    const __m512 px = _mm512_sub_ps(axis[sheared_.kx], _mm512_set1_ps(origin_[0]));
    const __m512 py = _mm512_sub_ps(axis[sheared_.ky], _mm512_set1_ps(origin_[1]));
    const __m512 pz = _mm512_sub_ps(axis[sheared_.kz], _mm512_set1_ps(origin_[2]));
    const __m512 x = _mm512_sub_ps(px, _mm512_mul_ps(_mm512_set1_ps(sheared_.shear_x), pz));
    const __m512 y = _mm512_sub_ps(py, _mm512_mul_ps(_mm512_set1_ps(sheared_.shear_y), pz));
    const __m512 z = _mm512_mul_ps(_mm512_set1_ps(sheared_.shear_z), pz);
    // Lane j takes lane j + 1 (j + 2); the last lanes repeat lane 15.
    const __m512i to_next = _mm512_setr_epi32(1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 15);
    const __m512i to_after_next = _mm512_setr_epi32(2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 15, 15);
    const __m512 x1 = _mm512_maskz_permutexvar_ps(0xffff, to_next, x);
    const __m512 y1 = _mm512_maskz_permutexvar_ps(0xffff, to_next, y);
    const __m512 x2 = _mm512_maskz_permutexvar_ps(0xffff, to_after_next, x);
    const __m512 y2 = _mm512_maskz_permutexvar_ps(0xffff, to_after_next, y);
    __m512 strip_edge = _mm512_sub_ps(_mm512_mul_ps(x1, y), _mm512_mul_ps(y1, x));
    __m512 diagonal = _mm512_sub_ps(_mm512_mul_ps(x2, y), _mm512_mul_ps(y2, x));
    const __m512 zero = _mm512_setzero_ps();
    // Only the strips' own edges count: a lane pair across two strips is no edge. An edge
    // from a vertex to itself (a turn's repeated triangle) is zero in double too: not redone.
    const __m512i index = _mm512_maskz_loadu_epi32(static_cast<__mmask16>((1u << pack.lanes) - 1), pack.vertex);
    const unsigned single_vertex_edges =
        _mm512_cmpeq_epi32_mask(index, _mm512_maskz_permutexvar_epi32(0xffff, to_next, index));
    const unsigned single_vertex_diagonals =
        _mm512_cmpeq_epi32_mask(index, _mm512_maskz_permutexvar_epi32(0xffff, to_after_next, index));
    if ((_mm512_cmp_ps_mask(strip_edge, zero, _CMP_EQ_OQ) & pack.strip_edges & ~single_vertex_edges) |
        (_mm512_cmp_ps_mask(diagonal, zero, _CMP_EQ_OQ) & pack.triangles & ~single_vertex_diagonals)) {
      // an exact zero is decided in double, per edge, as the watertight test does
      alignas(64) float xs[16], ys[16], strip_edges[16], diagonals[16];
      _mm512_store_ps(xs, x), _mm512_store_ps(ys, y);
      _mm512_store_ps(strip_edges, strip_edge), _mm512_store_ps(diagonals, diagonal);
      for (unsigned j = 0; j + 1 < PackedStrips::kLanes; ++j) {
        if ((pack.strip_edges >> j & 1u) && strip_edges[j] == 0.0f) {
          strip_edges[j] = edge_in_double(xs[j], ys[j], xs[j + 1], ys[j + 1]);
        }
        if ((pack.triangles >> j & 1u) && diagonals[j] == 0.0f) {
          diagonals[j] = edge_in_double(xs[j], ys[j], xs[j + 2], ys[j + 2]);
        }
      }
      strip_edge = _mm512_load_ps(strip_edges), diagonal = _mm512_load_ps(diagonals);
    }
    const __m512 sign = _mm512_set1_ps(-0.0f);
    const __m512 w0 = _mm512_maskz_permutexvar_ps(0xffff, to_next, strip_edge);
    const __m512 w1 = _mm512_xor_ps(diagonal, sign), w2 = strip_edge;
    const __mmask16 negative = _mm512_cmp_ps_mask(w0, zero, _CMP_LT_OQ) | _mm512_cmp_ps_mask(w1, zero, _CMP_LT_OQ) |
                               _mm512_cmp_ps_mask(w2, zero, _CMP_LT_OQ);
    const __mmask16 positive = _mm512_cmp_ps_mask(w0, zero, _CMP_GT_OQ) | _mm512_cmp_ps_mask(w1, zero, _CMP_GT_OQ) |
                               _mm512_cmp_ps_mask(w2, zero, _CMP_GT_OQ);
    const __m512 determinant = _mm512_add_ps(_mm512_add_ps(w0, w1), w2);
    const __m512 z1 = _mm512_maskz_permutexvar_ps(0xffff, to_next, z);
    const __m512 z2 = _mm512_maskz_permutexvar_ps(0xffff, to_after_next, z);
    const __m512 scaled_t =
        _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(w0, z), _mm512_mul_ps(w1, z1)), _mm512_mul_ps(w2, z2));
    // t * det against [tmin, tmax] * |det| without dividing; the sign of det flips t * det.
    const __mmask16 flip = _mm512_cmp_ps_mask(determinant, zero, _CMP_LT_OQ);
    const __m512 abs_determinant = _mm512_mask_xor_ps(determinant, flip, determinant, sign);
    const __m512 signed_t = _mm512_mask_xor_ps(scaled_t, flip, scaled_t, sign);
    const __mmask16 accepted =
        ~(negative & positive) & _mm512_cmp_ps_mask(determinant, zero, _CMP_NEQ_UQ) &
        _mm512_cmp_ps_mask(signed_t, _mm512_mul_ps(_mm512_set1_ps(tmin), abs_determinant), _CMP_GE_OQ) &
        _mm512_cmp_ps_mask(
            signed_t,
            _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(tmax), abs_determinant), _mm512_set1_ps(kDistancePrecheckSlack)),
            _CMP_LE_OQ);
    unsigned lanes = accepted & pack.triangles;
    if (lanes == 0) return;
    alignas(64) float determinants[16], scaled_ts[16], weights[3][16];
    _mm512_store_ps(determinants, determinant), _mm512_store_ps(scaled_ts, scaled_t);
    _mm512_store_ps(weights[0], w0), _mm512_store_ps(weights[1], w1), _mm512_store_ps(weights[2], w2);
    for (; lanes != 0; lanes &= lanes - 1) {
      const unsigned j = static_cast<unsigned>(std::countr_zero(lanes));
      const std::uint32_t first = pack.first_lane(j);
      const ray_strip::StripView strip(pack.strip_at[first]);
      if (offer_hit(strip, j - first, determinants[j], scaled_ts[j], weights[0][j], weights[1][j], weights[2][j]) &&
          kAnyHit) {
        return;
      }
    }
  }
#endif

  // Tests strip triangles [begin, end) by shared edges, 6 at a time.
  template <bool kAnyHit, typename Probe>
  void test_run(const ray_strip::StripView& strip, const glm::vec3* positions, std::uint32_t begin, std::uint32_t end,
                Probe& probe) {
    for (std::uint32_t chunk = begin; chunk < end; chunk += kRunTriangles) {
      test_chunk<kAnyHit>(strip, positions, chunk, std::min(end - chunk, kRunTriangles), probe);
      if (kAnyHit && found()) return;
    }
  }

 private:
  // Eight float lanes (GCC/Clang vector extensions: AVX2 here, plain scalar code elsewhere).
  using Lanes = float __attribute__((vector_size(32)));
  using LaneMask = std::int32_t __attribute__((vector_size(32)));

  // Lane j takes lane j + 1 (j + 2); the last lanes repeat lane 7.
  static Lanes next(Lanes v) { return __builtin_shufflevector(v, v, 1, 2, 3, 4, 5, 6, 7, 7); }
  static Lanes after_next(Lanes v) { return __builtin_shufflevector(v, v, 2, 3, 4, 5, 6, 7, 7, 7); }
  // Bit j: lane j of the mask is set.
  static unsigned bits_of(LaneMask mask) {
#if WAVETRACE_AVX2
    return static_cast<unsigned>(_mm256_movemask_ps((__m256)mask));
#else
    unsigned bits = 0;
    for (unsigned j = 0; j < kRunVertices; ++j) bits |= unsigned(mask[j] != 0) << j;
    return bits;
#endif
  }

  static float edge_in_double(float px, float py, float qx, float qy) {
    return static_cast<float>(double(qx) * double(py) - double(qy) * double(px));
  }

  // Triangles [first, first + count), count <= 6: lane j of every vector is vertex s[first + j]
  // (vertices past the run repeat the last one), edge (s[j], s[j+1]) or (s[j], s[j+2]), or
  // triangle j.
  template <bool kAnyHit, typename Probe>
  void test_chunk(const ray_strip::StripView& strip, const glm::vec3* positions, std::uint32_t first,
                  std::uint32_t count, Probe& probe) {
    const std::uint32_t vertices = count + 2;
    probe.read(strip.vertex_address(first), vertices * strip.index_width());
    if constexpr (Probe::kRecords) {
      for (std::uint32_t i = 0; i < vertices; ++i) probe.read(&positions[strip.vertex(first + i)], sizeof(glm::vec3));
    }
    Lanes px, py, pz;
    // Each vertex of the run is read whole (x, y, z by a masked load, which never reads past
    // the array) and the eight are transposed into lanes: on Zen 5 gathers of the indices and
    // then of each axis stalled this test for a third of its time even with the strip in L2.
    // Lanes past the run repeat its last vertex.
    std::uint32_t stored[kRunVertices];
    const std::uint32_t last = vertices - 1;
    const void* indices = strip.vertex_address(first);
    switch (strip.index_width()) {
      case 1:
        for (std::uint32_t i = 0; i < kRunVertices; ++i) stored[i] = static_cast<const std::uint8_t*>(indices)[std::min(i, last)];
        break;
      case 2:
        for (std::uint32_t i = 0; i < kRunVertices; ++i) stored[i] = static_cast<const std::uint16_t*>(indices)[std::min(i, last)];
        break;
      default:
        for (std::uint32_t i = 0; i < kRunVertices; ++i) stored[i] = static_cast<const std::uint32_t*>(indices)[std::min(i, last)];
    }
    const glm::vec3* base = positions + strip.vertex_base();
#if WAVETRACE_AVX2
    const __m128i xyz = _mm_setr_epi32(-1, -1, -1, 0);
    const auto vertex = [&](std::uint32_t i) { return _mm_maskload_ps(&base[stored[i]].x, xyz); };
    const __m256 row0 = _mm256_set_m128(vertex(4), vertex(0)), row1 = _mm256_set_m128(vertex(5), vertex(1));
    const __m256 row2 = _mm256_set_m128(vertex(6), vertex(2)), row3 = _mm256_set_m128(vertex(7), vertex(3));
    const __m256 xy01 = _mm256_unpacklo_ps(row0, row1), xy23 = _mm256_unpacklo_ps(row2, row3);  // x0 x1 y0 y1 | x4 ..
    const __m256 z01 = _mm256_unpackhi_ps(row0, row1), z23 = _mm256_unpackhi_ps(row2, row3);    // z0 z1 0 0 | z4 ..
    const Lanes axis[3] = {Lanes(_mm256_shuffle_ps(xy01, xy23, 0x44)), Lanes(_mm256_shuffle_ps(xy01, xy23, 0xee)),
                           Lanes(_mm256_shuffle_ps(z01, z23, 0x44))};
    px = axis[sheared_.kx] - origin_[0];
    py = axis[sheared_.ky] - origin_[1];
    pz = axis[sheared_.kz] - origin_[2];
#else
    for (std::uint32_t i = 0; i < kRunVertices; ++i) {
      const glm::vec3& p = base[stored[i]];
      px[i] = p[sheared_.kx] - origin_[0];
      py[i] = p[sheared_.ky] - origin_[1];
      pz[i] = p[sheared_.kz] - origin_[2];
    }
#endif
    const Lanes x = px - sheared_.shear_x * pz;
    const Lanes y = py - sheared_.shear_y * pz;
    const Lanes z = sheared_.shear_z * pz;
    // f(p, q) = q.x p.y - q.y p.x for the strip edges and the diagonals.
    const Lanes x1 = next(x), y1 = next(y), x2 = after_next(x), y2 = after_next(y);
    Lanes strip_edge = x1 * y - y1 * x;
    Lanes diagonal = x2 * y - y2 * x;
    // Only the run's edges count: lanes past it repeat the last vertex, whose edges are zero.
    // An edge from a vertex to itself (a turn's repeated triangle) is zero in double too: not
    // redone.
    using IndexLanes = std::uint32_t __attribute__((vector_size(32)));
    IndexLanes index;
    std::memcpy(&index, stored, sizeof(index));
    const unsigned single_vertex_edges =
        bits_of(LaneMask(index == __builtin_shufflevector(index, index, 1, 2, 3, 4, 5, 6, 7, 7)));
    const unsigned single_vertex_diagonals =
        bits_of(LaneMask(index == __builtin_shufflevector(index, index, 2, 3, 4, 5, 6, 7, 7, 7)));
    const unsigned strip_edges = ((2u << count) - 1) & ~single_vertex_edges;
    const unsigned triangles = (1u << count) - 1;
    if ((bits_of(strip_edge == 0.0f) & strip_edges) |
        (bits_of(diagonal == 0.0f) & triangles & ~single_vertex_diagonals)) {
      // an exact zero is decided in double, per edge, as the watertight test does
      for (std::uint32_t j = 0; j < count + 1; ++j) {
        if (strip_edge[j] == 0.0f) strip_edge[j] = edge_in_double(x[j], y[j], x[j + 1], y[j + 1]);
        if (j < count && diagonal[j] == 0.0f) diagonal[j] = edge_in_double(x[j], y[j], x[j + 2], y[j + 2]);
      }
    }
    const Lanes w0 = next(strip_edge), w1 = -diagonal, w2 = strip_edge;
    const LaneMask negative = (w0 < 0.0f) | (w1 < 0.0f) | (w2 < 0.0f);
    const LaneMask positive = (w0 > 0.0f) | (w1 > 0.0f) | (w2 > 0.0f);
    const Lanes determinant = w0 + w1 + w2;
    const Lanes scaled_t = w0 * z + w1 * next(z) + w2 * after_next(z);
    // t * det against [tmin, tmax] * |det| without dividing; the sign of det flips t * det.
    const LaneMask flip = determinant < 0.0f;
    const Lanes abs_determinant = flip ? -determinant : determinant;
    const Lanes signed_t = flip ? -scaled_t : scaled_t;
    const LaneMask accepted = ~(negative & positive) & (determinant != 0.0f) & (signed_t >= tmin * abs_determinant) &
                              (signed_t <= tmax * abs_determinant * kDistancePrecheckSlack);
    for (unsigned lanes = bits_of(accepted) & triangles; lanes != 0; lanes &= lanes - 1) {
      const unsigned j = static_cast<unsigned>(std::countr_zero(lanes));
      if (offer_hit(strip, first + j, determinant[j], scaled_t[j], w0[j], w1[j], w2[j]) && kAnyHit) return;
    }
  }

  // Strip triangle `triangle`, its scaled distance and corner weights over `determinant`:
  // kept when it is nearer than the hit so far (at the same t, when its mesh id is smaller).
  bool offer_hit(const ray_strip::StripView& strip, std::uint32_t triangle, float determinant, float scaled_t,
                 float w0, float w1, float w2) {
    const float inverse = 1.0f / determinant;
    const float t = scaled_t * inverse;
    if (!replaces_nearest(
            t, tmax, found(), [&] { return strip.triangle(triangle); },
            [&] { return ray_strip::StripView(hit.strip).triangle(hit.triangle); })) {
      return false;
    }
    tmax = t;
    hit.strip = strip.data();
    hit.triangle = triangle;
    hit.t = t;
    hit.weights[0] = w0 * inverse;
    hit.weights[1] = w1 * inverse;
    hit.weights[2] = w2 * inverse;
    return true;
  }

  WatertightRay sheared_;
  float origin_[3];  // the origin's kx, ky and kz coordinates
};

}  // namespace wavetrace
