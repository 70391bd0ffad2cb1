// Ray-box and ray-triangle kernels on the cases that break naive code: hits exactly on
// shared edges and vertices, axis-parallel and grazing rays, very different scales.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "wavetrace/kernels/plucker.hpp"
#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/kernels/watertight_lanes.hpp"

namespace wavetrace {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

bool watertight_hit(glm::vec3 o, glm::vec3 d, glm::vec3 a, glm::vec3 b, glm::vec3 c, TriangleHit* out = nullptr) {
  TriangleHit hit{};  // a miss leaves it as it was: zeros, never stack garbage (a NaN there failed a run)
  const bool found = intersect_watertight(make_watertight_ray(o, d), a, b, c, 0.0f, kInf, hit);
  if (out) *out = hit;
  return found;
}

TEST(RayBox, ZeroDirectionComponentsAreHandled) {
  const glm::vec3 lower(0.0f), upper(1.0f);
  // Axis-parallel ray inside the slab of the zero components.
  EXPECT_FLOAT_EQ(intersect_box(make_box_ray({0.5f, 0.5f, -1.0f}, {0, 0, 1}), lower, upper, 0.0f, kInf), 1.0f);
  // Outside the slab of a zero component: miss, not NaN.
  EXPECT_EQ(intersect_box(make_box_ray({1.5f, 0.5f, -1.0f}, {0, 0, 1}), lower, upper, 0.0f, kInf), kInf);
  // Origin exactly on a slab plane with zero direction there: counts as inside (conservative).
  EXPECT_FLOAT_EQ(intersect_box(make_box_ray({1.0f, 0.5f, -1.0f}, {0, 0, 1}), lower, upper, 0.0f, kInf), 1.0f);
  EXPECT_FLOAT_EQ(intersect_box(make_box_ray({0.0f, 0.0f, -1.0f}, {0, 0, 1}), lower, upper, 0.0f, kInf), 1.0f);
  // Negative zero behaves like zero.
  EXPECT_FLOAT_EQ(intersect_box(make_box_ray({0.5f, 0.5f, 2.0f}, {-0.0f, 0.0f, -1.0f}), lower, upper, 0.0f, kInf), 1.0f);
}

TEST(RayBox, OriginInsideAndIntervalClipping) {
  const glm::vec3 lower(-1.0f), upper(1.0f);
  EXPECT_FLOAT_EQ(intersect_box(make_box_ray({0, 0, 0}, {0.3f, -0.2f, 0.9f}), lower, upper, 0.0f, kInf), 0.0f);
  EXPECT_EQ(intersect_box(make_box_ray({0, 0, -5}, {0, 0, 1}), lower, upper, 0.0f, 3.9f), kInf);  // ends before
  EXPECT_EQ(intersect_box(make_box_ray({0, 0, -5}, {0, 0, 1}), lower, upper, 6.1f, kInf), kInf);  // starts after
  EXPECT_EQ(intersect_box(make_box_ray({0, 0, -5}, {0, 0, -1}), lower, upper, 0.0f, kInf), kInf);  // points away
}

TEST(RayBox, GrazingTheFaceIsAHit) {
  // A ray running exactly along the box's top face.
  EXPECT_NE(intersect_box(make_box_ray({-2.0f, 1.0f, 0.5f}, {1, 0, 0}), glm::vec3(0.0f), glm::vec3(1.0f), 0.0f, kInf), kInf);
  // Flat box (zero thickness, like the bounds of an axis-aligned triangle).
  EXPECT_NE(intersect_box(make_box_ray({0.5f, 0.5f, 1.0f}, {0.1f, 0.0f, -1.0f}), glm::vec3(0.0f), glm::vec3(1.0f, 1.0f, 0.0f),
                          0.0f, kInf),
            kInf);
}

TEST(RayBox, SoaVersionMatchesScalar) {
  constexpr std::size_t n = 37;
  float ox[n], oy[n], oz[n], ix[n], iy[n], iz[n], tmin[n], tmax[n], entry[n];
  const glm::vec3 lower(-0.5f, -0.25f, 0.0f), upper(0.5f, 0.75f, 2.0f);
  for (std::size_t i = 0; i < n; ++i) {
    const UnitPair a = unit_pair(random_bits(std::uint32_t(i), 0, 0, RandomPurpose::benchmark));
    const UnitPair b = unit_pair(random_bits(std::uint32_t(i), 0, 1, RandomPurpose::benchmark));
    const glm::vec3 origin(4 * a.first - 2, 4 * a.second - 2, -3.0f);
    const glm::vec3 direction(b.first - 0.5f, i % 5 == 0 ? 0.0f : b.second - 0.5f, 1.0f);
    const BoxRay ray = make_box_ray(origin, direction);
    ox[i] = origin.x, oy[i] = origin.y, oz[i] = origin.z;
    ix[i] = ray.inverse_direction.x, iy[i] = ray.inverse_direction.y, iz[i] = ray.inverse_direction.z;
    tmin[i] = 0.0f, tmax[i] = kInf;
  }
  intersect_box_soa(ox, oy, oz, ix, iy, iz, tmin, tmax, n, lower, upper, entry);
  for (std::size_t i = 0; i < n; ++i) {
    const BoxRay ray{{ox[i], oy[i], oz[i]}, {ix[i], iy[i], iz[i]}};
    EXPECT_EQ(entry[i], intersect_box(ray, lower, upper, 0.0f, kInf)) << i;
  }
}

TEST(RayBox, ManyBoxesInLanesMatchScalar) {
  constexpr std::size_t n = 37;
  float lower[3][n], upper[3][n], entry[n];
  for (std::size_t k = 0; k < n; ++k) {
    const UnitPair a = unit_pair(random_bits(std::uint32_t(k), 1, 0, RandomPurpose::benchmark));
    const UnitPair b = unit_pair(random_bits(std::uint32_t(k), 1, 1, RandomPurpose::benchmark));
    const glm::vec3 low(2 * a.first - 1, 2 * a.second - 1, k % 3 == 0 ? 0.5f : a.first);
    const glm::vec3 high = low + glm::vec3(b.first, k % 4 == 0 ? 0.0f : b.second, 0.5f);  // some flat
    for (int axis = 0; axis < 3; ++axis) lower[axis][k] = low[axis], upper[axis][k] = high[axis];
  }
  const float* const lowers[3] = {lower[0], lower[1], lower[2]};
  const float* const uppers[3] = {upper[0], upper[1], upper[2]};
  for (const glm::vec3 direction : {glm::vec3(0.1f, 0.2f, 1.0f), glm::vec3(0.0f, -0.3f, 1.0f), glm::vec3(-1, 0, 0)}) {
    const BoxRay ray = make_box_ray(glm::vec3(0.1f, -0.2f, -2.0f), direction);
    for (const float tmax : {kInf, 2.5f}) {
      intersect_boxes_soa(ray, lowers, uppers, n, 0.0f, tmax, entry);
      std::size_t entered = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const glm::vec3 low(lower[0][k], lower[1][k], lower[2][k]), high(upper[0][k], upper[1][k], upper[2][k]);
        EXPECT_EQ(entry[k], intersect_box(ray, low, high, 0.0f, tmax)) << k;
        entered += entry[k] != kInf;
      }
      if (direction.z > 0.0f && tmax == kInf) EXPECT_GT(entered, 0u);
    }
  }
}

TEST(Watertight, SharedEdgeAndVertexAreNeverMissed) {
  // A fan of triangles around (0.3, 0.3, 0) covering a hexagon; rays exactly through the
  // centre (a shared vertex) and exactly through points of each shared edge.
  const glm::vec3 center(0.3f, 0.3f, 0.0f);
  glm::vec3 rim[6];
  for (int k = 0; k < 6; ++k) rim[k] = center + glm::vec3(std::cos(k * 1.0471976f), std::sin(k * 1.0471976f), 0.0f) * 0.7f;
  const auto count_hits = [&](glm::vec3 origin, glm::vec3 direction) {
    int hits = 0;
    for (int k = 0; k < 6; ++k) hits += watertight_hit(origin, direction, center, rim[k], rim[(k + 1) % 6]);
    return hits;
  };
  for (const glm::vec3 direction : {glm::vec3(0, 0, -1), glm::normalize(glm::vec3(0.31f, -0.17f, -1.0f))}) {
    EXPECT_GE(count_hits(center - direction * 3.0f, direction), 1);
    for (int k = 0; k < 6; ++k) {
      for (float s : {0.1f, 0.37f, 0.5f, 0.93f}) {
        const glm::vec3 on_edge = center + (rim[k] - center) * s;
        EXPECT_GE(count_hits(on_edge - direction * 2.0f, direction), 1) << k << " " << s;
      }
    }
  }
}

TEST(Watertight, VertexHitGivesBarycentricCorner) {
  TriangleHit hit;
  ASSERT_TRUE(watertight_hit({1, 0, 1}, {0, 0, -1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, &hit));
  EXPECT_FLOAT_EQ(hit.t, 1.0f);
  EXPECT_FLOAT_EQ(hit.u, 1.0f);  // the second vertex
  EXPECT_FLOAT_EQ(hit.v, 0.0f);
}

TEST(Watertight, GrazingRayInThePlaneMissesCleanly) {
  TriangleHit hit{};
  EXPECT_FALSE(watertight_hit({-1.0f, 0.25f, 0.0f}, {1, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, &hit));
  EXPECT_FALSE(std::isnan(hit.t));
}

TEST(Watertight, BothFacesAndIntervalLimits) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  TriangleHit hit;
  EXPECT_TRUE(intersect_watertight(make_watertight_ray({0.2f, 0.2f, 1}, {0, 0, -1}), a, b, c, 0.0f, kInf, hit));
  EXPECT_TRUE(intersect_watertight(make_watertight_ray({0.2f, 0.2f, -1}, {0, 0, 1}), a, b, c, 0.0f, kInf, hit));
  EXPECT_FALSE(intersect_watertight(make_watertight_ray({0.2f, 0.2f, 1}, {0, 0, -1}), a, b, c, 0.0f, 0.99f, hit));
  EXPECT_FALSE(intersect_watertight(make_watertight_ray({0.2f, 0.2f, 1}, {0, 0, -1}), a, b, c, 1.01f, kInf, hit));
  EXPECT_FALSE(intersect_watertight(make_watertight_ray({0.2f, 0.2f, 1}, {0, 0, 1}), a, b, c, 0.0f, kInf, hit));
}

TEST(Watertight, TrianglesOfVeryDifferentScales) {
  for (const float scale : {1e-5f, 1e-2f, 1.0f, 1e3f, 1e6f}) {
    const glm::vec3 offset(scale * 7.0f, -scale * 3.0f, scale * 11.0f);
    const glm::vec3 a = offset, b = offset + glm::vec3(scale, 0, 0), c = offset + glm::vec3(0, scale, 0);
    TriangleHit hit;
    const glm::vec3 origin = offset + glm::vec3(0.25f * scale, 0.25f * scale, 2.0f * scale);
    ASSERT_TRUE(watertight_hit(origin, {0, 0, -1}, a, b, c, &hit)) << scale;
    EXPECT_NEAR(hit.t, 2.0f * scale, 1e-5f * scale) << scale;
    EXPECT_NEAR(hit.u, 0.25f, 1e-4f) << scale;
    EXPECT_NEAR(hit.v, 0.25f, 1e-4f) << scale;
    EXPECT_FALSE(watertight_hit(origin + glm::vec3(2.0f * scale, 0, 0), {0, 0, -1}, a, b, c)) << scale;
  }
}

#if WAVETRACE_AVX2
// Each lane of the SIMD test against the scalar test on the same triangle: a candidate lane is
// the scalar hit, bit for bit, once its t is checked against tmax; a rejected lane is a scalar
// miss; a lane on an edge (left to the scalar test by the caller) is counted, so that the
// lattice below is known to reach that case.
template <int kLanes>
void expect_lanes_match_scalar_test() {
  // Triangles of a unit lattice in z = 0 (shared edges and vertices) and tilted random ones.
  std::vector<std::array<glm::vec3, 3>> triangles;
  for (int x = -2; x < 2; ++x) {
    for (int y = -2; y < 2; ++y) {
      const glm::vec3 p(float(x), float(y), 0.0f);
      triangles.push_back({p, p + glm::vec3(1, 0, 0), p + glm::vec3(1, 1, 0)});
      triangles.push_back({p, p + glm::vec3(1, 1, 0), p + glm::vec3(0, 1, 0)});
    }
  }
  for (std::uint32_t i = 0; i < 32; ++i) {
    std::array<glm::vec3, 3> t;
    for (int c = 0; c < 3; ++c) {
      const UnitPair p = unit_pair(random_bits(i, c, 7, RandomPurpose::benchmark));
      const UnitPair q = unit_pair(random_bits(i, c, 8, RandomPurpose::benchmark));
      t[c] = glm::vec3(4 * p.first - 2, 4 * p.second - 2, q.first - 0.5f);
    }
    triangles.push_back(t);
  }
  int hits = 0, on_edges = 0, lanes_compared = 0;
  for (std::uint32_t r = 0; r < 4000; ++r) {
    const UnitPair p = unit_pair(random_bits(r, 0, 2, RandomPurpose::benchmark));
    const UnitPair q = unit_pair(random_bits(r, 0, 3, RandomPurpose::benchmark));
    // Every fourth ray starts on the half-lattice and runs straight down: through edges and
    // vertices exactly. The others run anywhere, some away from the triangles (both faces).
    const bool on_lattice = r % 4 == 0;
    const glm::vec3 origin = on_lattice ? glm::vec3(std::floor(8 * p.first - 4) * 0.5f, std::floor(8 * p.second - 4) * 0.5f, 2.0f)
                                        : glm::vec3(4 * p.first - 2, 4 * p.second - 2, r % 3 == 0 ? -2.0f : 2.0f);
    const glm::vec3 direction = on_lattice ? glm::vec3(0, 0, -1)
                                           : glm::normalize(glm::vec3(q.first - 0.5f, q.second - 0.5f, origin.z > 0 ? -1.0f : 1.0f));
    const WatertightRay ray = make_watertight_ray(origin, direction);
    const float tmin = 0.0f, tmax = r % 5 == 0 ? 1.9f : kInf;  // some hits lie beyond a tmax
    for (std::size_t base = 0; base < triangles.size(); base += kLanes) {
      TriangleLanes<kLanes> lanes{};
      const std::size_t count = std::min<std::size_t>(kLanes, triangles.size() - base);
      for (std::size_t k = 0; k < count; ++k) {
        for (int c = 0; c < 3; ++c) {
          for (int axis = 0; axis < 3; ++axis) lanes.corner[c][axis][k] = triangles[base + k][c][axis];
        }
      }
      WatertightLanes<kLanes> result;
      intersect_watertight_lanes(ray, lanes, (1u << count) - 1, tmin, tmax, result);
      EXPECT_EQ((result.candidates | result.on_edge) >> count, 0u);
      for (std::size_t k = 0; k < count; ++k) {
        const auto& t = triangles[base + k];
        TriangleHit hit{};
        const bool scalar = intersect_watertight(ray, t[0], t[1], t[2], tmin, tmax, hit);
        if (result.on_edge >> k & 1u) {
          ++on_edges;
          continue;
        }
        ++lanes_compared;
        const bool lane = (result.candidates >> k & 1u) && result.t[k] <= tmax;
        ASSERT_EQ(lane, scalar) << "ray " << r << " triangle " << base + k;
        if (!scalar) continue;
        ++hits;
        EXPECT_EQ(std::bit_cast<std::uint32_t>(result.t[k]), std::bit_cast<std::uint32_t>(hit.t));
        EXPECT_EQ(std::bit_cast<std::uint32_t>(result.u[k]), std::bit_cast<std::uint32_t>(hit.u));
        EXPECT_EQ(std::bit_cast<std::uint32_t>(result.v[k]), std::bit_cast<std::uint32_t>(hit.v));
      }
    }
  }
  EXPECT_GT(hits, 2000);
  EXPECT_GT(on_edges, 500);
  EXPECT_GT(lanes_compared, 100000);
}

TEST(TriangleTests, FourLaneWatertightTestIsTheScalarTestBitForBit) { expect_lanes_match_scalar_test<4>(); }
TEST(TriangleTests, EightLaneWatertightTestIsTheScalarTestBitForBit) { expect_lanes_match_scalar_test<8>(); }
#endif

TEST(TriangleTests, MollerTrumboreAndPluckerAgreeAwayFromEdges) {
  const glm::vec3 a(-0.4f, -0.3f, 0.1f), b(0.7f, -0.2f, -0.2f), c(0.1f, 0.8f, 0.3f);
  int agreements = 0, hits = 0;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    const UnitPair p = unit_pair(random_bits(i, 0, 0, RandomPurpose::benchmark));
    const UnitPair q = unit_pair(random_bits(i, 0, 1, RandomPurpose::benchmark));
    const glm::vec3 origin(2 * p.first - 1, 2 * p.second - 1, 3.0f);
    const glm::vec3 direction = glm::normalize(glm::vec3(0.4f * (q.first - 0.5f), 0.4f * (q.second - 0.5f), -1.0f));
    TriangleHit w{}, m{}, pl{};
    const bool hw = intersect_watertight(make_watertight_ray(origin, direction), a, b, c, 0.0f, kInf, w);
    const bool hm = intersect_moller_trumbore(origin, direction, a, b, c, 0.0f, kInf, m);
    const bool hp = intersect_plucker(origin, direction, a, b, c, 0.0f, kInf, pl);
    if (hw == hm && hw == hp) ++agreements;
    if (hw && hm && hp) {
      ++hits;
      EXPECT_NEAR(w.t, m.t, 1e-5f);
      EXPECT_NEAR(w.t, pl.t, 1e-5f);
      EXPECT_NEAR(w.u, m.u, 1e-4f);
      EXPECT_NEAR(w.v, pl.v, 1e-4f);
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GE(agreements, 19990);  // only rays within float error of an edge may differ
}

TEST(Plucker, EdgeSignFlipsWithEdgeDirectionAndSide) {
  const glm::vec3 origin(0, 0, 1), direction(0, 0, -1);
  const float left = plucker_edge_side(origin, direction, {-1, -1, 0}, {1, -1, 0});
  EXPECT_NE(left, 0.0f);
  EXPECT_EQ(plucker_edge_side(origin, direction, {1, -1, 0}, {-1, -1, 0}), -left);
  EXPECT_LT(plucker_edge_side(origin, direction, {-1, 1, 0}, {1, 1, 0}) * left, 0.0f);
  EXPECT_EQ(plucker_edge_side(origin, direction, {-1, 0, 0}, {1, 0, 0}), 0.0f);  // through the edge
}

}  // namespace
}  // namespace wavetrace
