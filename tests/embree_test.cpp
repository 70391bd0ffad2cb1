// The Embree reference against analytic answers: distances, primitives, barycentrics,
// ray intervals, any-hit, memory accounting.
#include <chrono>
#include <cmath>
#include <mutex>
#include <set>
#include <thread>
#include <limits>
#include <stdexcept>
#include <tuple>

#include <gtest/gtest.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/pipeline/tracing_arena.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"

namespace wavetrace {

// ctest names the parameters rather than printing their bytes (found by ADL in wavetrace).
void PrintTo(EmbreeMode mode, std::ostream* out) { *out << to_string(mode); }
void PrintTo(EmbreeQueries queries, std::ostream* out) { *out << to_string(queries); }

namespace {

// Two triangles forming the unit square [0,1]^2 at z = 0.
TriangleMesh unit_square() {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  validate_and_clean(mesh, "square");
  return mesh;
}

void set_ray(RayBatch& rays, std::size_t i, glm::vec3 origin, glm::vec3 direction, float tmin = 0.0f,
             float tmax = std::numeric_limits<float>::infinity()) {
  rays.set_geometry(i, origin, direction, tmin, tmax);
  rays.flags[i] = ray_flags::alive;
  rays.kind[i] = RayKind::camera;
}

class EmbreeModes : public ::testing::TestWithParam<std::tuple<EmbreeMode, EmbreeQueries>> {};

TEST_P(EmbreeModes, HitsTheSquareWhereGeometrySays) {
  const TriangleMesh mesh = unit_square();
  AcceleratorOptions options;
  options.embree.mode = std::get<0>(GetParam());
  options.embree.queries = std::get<1>(GetParam());
  const auto accel = make_accelerator(mesh, options);
  RayBatch rays(8);
  HitBatch hits(8);
  set_ray(rays, 0, {0.75f, 0.25f, 2.0f}, {0, 0, -1});         // lower-right triangle, t = 2
  set_ray(rays, 1, {0.25f, 0.75f, -3.0f}, {0, 0, 1});         // upper-left triangle from below, t = 3
  set_ray(rays, 2, {1.5f, 0.5f, 1.0f}, {0, 0, -1});           // beside the square: miss
  set_ray(rays, 3, {0.5f, 0.25f, 2.0f}, {0, 0, -1}, 0.0f, 1.5f);  // stops short: miss
  set_ray(rays, 4, {0.5f, 0.25f, 2.0f}, {0, 0, -1}, 2.5f);    // starts past it: miss
  set_ray(rays, 5, {0.5f, 0.25f, 1.0f}, {0.0f, 0.0f, -2.0f}); // unnormalized direction: t = 0.5
  set_ray(rays, 6, {0.75f, 0.25f, 2.0f}, {0, 0, -1});
  rays.flags[6] = 0;  // dead rays are skipped
  rays.count = 7;
  accel->intersect_closest(rays, hits, rays.all());

  EXPECT_FLOAT_EQ(hits.t[0], 2.0f);
  EXPECT_EQ(hits.primitive[0], 0u);
  // Embree's u, v weight the second and third vertex: (0.75, 0.25) = 0.5 v1 + 0.25 v2 + 0.25 v0.
  EXPECT_NEAR(hits.u[0], 0.5f, 1e-6f);
  EXPECT_NEAR(hits.v[0], 0.25f, 1e-6f);
  EXPECT_FLOAT_EQ(hits.t[1], 3.0f);
  EXPECT_EQ(hits.primitive[1], 1u);
  for (int miss : {2, 3, 4, 6}) {
    EXPECT_EQ(hits.primitive[miss], kInvalidPrimitive) << miss;
    EXPECT_TRUE(std::isinf(hits.t[miss])) << miss;
  }
  EXPECT_FLOAT_EQ(hits.t[5], 0.5f);

  accel->intersect_any(rays, hits, rays.all());
  EXPECT_TRUE(hits.is_hit(0));
  EXPECT_TRUE(hits.is_hit(1));
  EXPECT_FALSE(hits.is_hit(2));
  EXPECT_FALSE(hits.is_hit(3));
  EXPECT_FALSE(hits.is_hit(4));
  EXPECT_TRUE(hits.is_hit(5));
  EXPECT_FALSE(hits.is_hit(6));
}

INSTANTIATE_TEST_SUITE_P(AllModes, EmbreeModes,
                         ::testing::Combine(::testing::Values(EmbreeMode::standard, EmbreeMode::compact,
                                                              EmbreeMode::robust),
                                            ::testing::Values(EmbreeQueries::single, EmbreeQueries::stream)),
                         [](const auto& info) {
                           return to_string(std::get<0>(info.param)) + "_" + to_string(std::get<1>(info.param));
                         });

// The stream entries answer exactly what rtcIntersect1/rtcOccluded1 answer, ray for ray, for
// closest, coherent and any-hit queries over a range with dead rays and short segments; and
// the distance queries (no surfaces) the closest hits' t, primitive, u and v, both ways.
TEST(Embree, StreamQueriesAnswerWhatSingleQueriesAnswer) {
  const Scene room = make_builtin_scene("builtin:room:20k");
  AcceleratorOptions single_options, stream_options;
  single_options.embree.queries = EmbreeQueries::single;
  stream_options.embree.queries = EmbreeQueries::stream;
  const auto single = make_accelerator(room.mesh, single_options);
  const auto stream = make_accelerator(room.mesh, stream_options);
  constexpr std::size_t kRays = 1000;
  RayBatch rays(kRays);
  const glm::vec3 center = 0.5f * (room.bounds.lower + room.bounds.upper);
  for (std::size_t i = 0; i < kRays; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / float(kRays), phi = 2.39996f * float(i);
    const float r = std::sqrt(1.0f - z * z);
    const float tmax = i % 3 == 0 ? 0.5f : std::numeric_limits<float>::infinity();
    set_ray(rays, i, center, {r * std::cos(phi), r * std::sin(phi), z}, 0.0f, tmax);
    if (i % 7 == 0) rays.flags[i] = 0;
  }
  rays.count = kRays;
  const RayRange range{3, kRays - 2};
  for (int query = 0; query < 5; ++query) {
    HitBatch expected(kRays), found(kRays);
    if (query >= 3) {
      single->intersect_closest(rays, expected, range);
      (query == 3 ? stream : single)->intersect_distance(rays, found, range);
    } else if (query == 0) {
      single->intersect_closest(rays, expected, range);
      stream->intersect_closest(rays, found, range);
    } else if (query == 1) {
      single->intersect_coherent(rays, expected, range);
      stream->intersect_coherent(rays, found, range);
    } else {
      single->intersect_any(rays, expected, range);
      stream->intersect_any(rays, found, range);
    }
    std::size_t hit_count = 0;
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      ASSERT_EQ(found.primitive[i], expected.primitive[i]) << "query " << query << " ray " << i;
      hit_count += expected.is_hit(i);
      if (query == 2 || !expected.is_hit(i)) continue;
      EXPECT_EQ(found.t[i], expected.t[i]) << i;
      EXPECT_EQ(found.u[i], expected.u[i]) << i;
      EXPECT_EQ(found.v[i], expected.v[i]) << i;
      if (query >= 3) continue;  // a distance query leaves the surface unset
      EXPECT_EQ(found.point(i), expected.point(i)) << i;
      EXPECT_EQ(found.normal(i), expected.normal(i)) << i;
    }
    EXPECT_GT(hit_count, range.size() / 3) << "query " << query;
    for (std::uint32_t i = (range.begin + 6) / 7 * 7; i < range.end; i += 7) EXPECT_FALSE(found.is_hit(i)) << "dead ray " << i;
  }
}

TEST(Embree, RangesTouchOnlyTheirRays) {
  const TriangleMesh mesh = unit_square();
  const auto accel = make_accelerator(mesh, {});
  RayBatch rays(4);
  HitBatch hits(4);
  for (std::size_t i = 0; i < 4; ++i) set_ray(rays, i, {0.75f, 0.25f, 1.0f}, {0, 0, -1});
  rays.count = 4;
  hits.primitive[0] = hits.primitive[3] = 1234;
  accel->intersect_closest(rays, hits, {1, 3});
  EXPECT_EQ(hits.primitive[0], 1234u);
  EXPECT_EQ(hits.primitive[1], 0u);
  EXPECT_EQ(hits.primitive[2], 0u);
  EXPECT_EQ(hits.primitive[3], 1234u);
}

TEST(Embree, RaysFromTheCenterOfASphereHitAtTheRadius) {
  // Undisplaced distance check on the closed sphere: every ray from inside hits.
  const Scene sphere = make_builtin_scene("builtin:sphere:20k");
  const auto accel = make_accelerator(sphere.mesh, {});
  RayBatch rays(512);
  HitBatch hits(512);
  for (std::size_t i = 0; i < 512; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / 512.0f, phi = 2.39996f * float(i);
    const float r = std::sqrt(1.0f - z * z);
    set_ray(rays, i, {0, 0, 0}, {r * std::cos(phi), r * std::sin(phi), z});
  }
  rays.count = 512;
  accel->intersect_closest(rays, hits, rays.all());
  for (std::size_t i = 0; i < 512; ++i) {
    ASSERT_TRUE(hits.is_hit(i)) << i;
    EXPECT_GT(hits.t[i], 0.75f);  // radius 1 displaced by at most 12% (of 0.5 noise amplitude ~ 1)
    EXPECT_LT(hits.t[i], 1.25f);
  }
}

TEST(Embree, KernelsForcedToAvx2AnswerWhatTheNativeOnesAnswer) {
  // accel.embree.isa = avx2 makes a device of Embree's AVX2 kernels (the name says so); on any
  // CPU of this project's kind the hits are the native kernels', within float rounding.
  const Scene sphere = make_builtin_scene("builtin:sphere:20k");
  AcceleratorOptions forced;
  forced.embree.isa = "avx2";
  const auto native = make_accelerator(sphere.mesh, {});
  const auto avx2 = make_accelerator(sphere.mesh, forced);
  EXPECT_EQ(avx2->name(), "embree-avx2");
  RayBatch rays(512);
  HitBatch native_hits(512), avx2_hits(512);
  for (std::size_t i = 0; i < 512; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / 512.0f, phi = 2.39996f * float(i);
    const float r = std::sqrt(1.0f - z * z);
    set_ray(rays, i, {0.1f, -0.2f, 0.05f}, {r * std::cos(phi), r * std::sin(phi), z});
  }
  rays.count = 512;
  native->intersect_closest(rays, native_hits, rays.all());
  avx2->intersect_closest(rays, avx2_hits, rays.all());
  for (std::size_t i = 0; i < 512; ++i) {
    ASSERT_TRUE(avx2_hits.is_hit(i)) << i;
    EXPECT_NEAR(avx2_hits.t[i], native_hits.t[i], 1e-5f) << i;
  }
  EXPECT_THROW(parse_embree_isa("avx9"), std::invalid_argument);
}

TEST(Embree, MemoryCountsHierarchyAndMeshBuffers) {
  const Scene sphere = make_builtin_scene("builtin:sphere:20k");
  AcceleratorOptions standard, compact;
  compact.embree.mode = EmbreeMode::compact;
  const auto a = make_accelerator(sphere.mesh, standard);
  const auto b = make_accelerator(sphere.mesh, compact);
  EXPECT_EQ(a->memory().geometry, sphere.mesh.vertex_count() * 12 + sphere.mesh.triangle_count() * 12);
  EXPECT_GT(a->memory().hierarchy, 0u);
  EXPECT_LT(b->memory().hierarchy, a->memory().hierarchy);
  EXPECT_GE(a->build().peak_bytes, a->memory().total());
  EXPECT_GT(a->build().seconds, 0.0);
  EXPECT_EQ(a->name(), "embree");
  EXPECT_EQ(b->name(), "embree-compact");
}

TEST(Embree, UnknownAcceleratorIsAnError) {
  const TriangleMesh mesh = unit_square();
  AcceleratorOptions options;
  options.type = "octree";
  try {
    make_accelerator(mesh, options);
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("octree"), std::string::npos);
  }
}

// An Embree device asked for more threads than there are cores must not cap our arenas at the
// cores: Embree's TBB scheduler holds min(threads, cores) as a process-wide limit, so before,
// `--threads 8` on a 2-core machine traced on 2 threads while an Embree device lived.
TEST(Embree, ADeviceLeavesArenasOfMoreThreadsThanCoresTheirThreads) {
  const int threads = tbb::info::default_concurrency() * 4;
  AcceleratorOptions options;
  options.type = "embree";
  options.embree.threads = threads;
  const auto accel = make_accelerator(unit_square(), options);
  TracingArena arena(threads);
  std::mutex mutex;
  std::set<std::thread::id> seen;
  arena.execute([&] {
    tbb::parallel_for(0, threads * 8, [&](int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // every thread gets a turn
      std::lock_guard lock(mutex);
      seen.insert(std::this_thread::get_id());
    });
  });
  EXPECT_EQ(seen.size(), std::size_t(threads));
}

}  // namespace
}  // namespace wavetrace
