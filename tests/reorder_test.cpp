// Ray reordering: curve keys, the proxy, approx_hit's retirement of box misses, zsort's
// order, and the image that no heuristic or curve may change.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "wavetrace/accel/proxy/cluster_simplify.hpp"
#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/accel/proxy/stochastic_simplify.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/reorder_bench.hpp"
#include "wavetrace/kernels/radix_sort.hpp"
#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/space_filling_curve.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/stages/zsort.hpp"
#include "collecting_output.hpp"

namespace wavetrace {
namespace {

template <int D, int kBits, typename KeyFunction>
void expect_curve_visits_every_cell_once(KeyFunction key, bool adjacent_steps) {
  std::map<std::uint64_t, std::array<std::uint32_t, D>> by_key;
  const std::uint32_t side = 1u << kBits;
  std::array<std::uint32_t, D> cell{};
  std::size_t cells = 1;
  for (int d = 0; d < D; ++d) cells *= side;
  for (std::size_t n = 0; n < cells; ++n) {
    std::size_t rest = n;
    for (int d = 0; d < D; ++d) {
      cell[d] = std::uint32_t(rest % side);
      rest /= side;
    }
    by_key[key(cell)] = cell;
  }
  ASSERT_EQ(by_key.size(), cells);  // a bijection
  EXPECT_EQ(by_key.begin()->first, 0u);
  EXPECT_EQ(by_key.rbegin()->first, cells - 1);
  if (!adjacent_steps) return;
  const std::array<std::uint32_t, D>* previous = nullptr;
  for (const auto& [k, c] : by_key) {
    if (previous != nullptr) {
      std::uint32_t distance = 0;
      for (int d = 0; d < D; ++d) distance += c[d] > (*previous)[d] ? c[d] - (*previous)[d] : (*previous)[d] - c[d];
      ASSERT_EQ(distance, 1u) << "key " << k;  // each Hilbert step moves to a neighbouring cell
    }
    previous = &c;
  }
}

TEST(SpaceFillingCurve, MortonInterleavesWithTheFirstDimensionHighest) {
  EXPECT_EQ((morton_key<3, 20>({1, 0, 0})), 4u);
  EXPECT_EQ((morton_key<3, 20>({0, 0, 1})), 1u);
  EXPECT_EQ((morton_key<3, 20>({0, 1, 0})), 2u);
  EXPECT_EQ((morton_key<3, 20>({2, 0, 0})), 32u);
  EXPECT_EQ((morton_key<3, 20>({(1u << 20) - 1, (1u << 20) - 1, (1u << 20) - 1})), (std::uint64_t{1} << 60) - 1);
  EXPECT_EQ((morton_key<5, 12>({0, 0, 0, 0, 1})), 1u);
  expect_curve_visits_every_cell_once<3, 3>([](auto c) { return morton_key<3, 3>(c); }, false);
  expect_curve_visits_every_cell_once<6, 2>([](auto c) { return morton_key<6, 2>(c); }, false);
}

TEST(SpaceFillingCurve, HilbertStepsBetweenNeighbouringCells) {
  expect_curve_visits_every_cell_once<2, 4>([](auto c) { return hilbert_key<2, 4>(c); }, true);
  expect_curve_visits_every_cell_once<3, 3>([](auto c) { return hilbert_key<3, 3>(c); }, true);
  expect_curve_visits_every_cell_once<5, 2>([](auto c) { return hilbert_key<5, 2>(c); }, true);
}

// Keys of Skilling's transform as written with a branch a bit (before the transform went
// branch-free): orders, and so every paged figure measured with Hilbert keys, stay the same.
TEST(SpaceFillingCurve, HilbertKeysKeepTheirValues) {
  EXPECT_EQ((hilbert_key<3, 20>({123456, 654321, 1000000})), 310068032564400129u);
  EXPECT_EQ((hilbert_key<5, 12>({1, 4095, 2048, 777, 3000})), 341701500636341553u);
  EXPECT_EQ((hilbert_key<6, 10>({1023, 0, 512, 300, 17, 900})), 884143384108841290u);
}

template <int D, int kBits>
void expect_lanes_match_one_cell_at_a_time(std::mt19937& random) {
  std::uniform_int_distribution<std::uint32_t> coordinate(0, (std::uint32_t{1} << kBits) - 1);
  for (int round = 0; round < 1000; ++round) {
    std::uint32_t cells[D][kHilbertLanes];
    for (auto& axis : cells) {
      for (std::uint32_t& value : axis) value = coordinate(random);
    }
    std::uint64_t keys[kHilbertLanes];
    hilbert_keys<D, kBits>(cells, keys);
    for (std::size_t lane = 0; lane < kHilbertLanes; ++lane) {
      std::array<std::uint32_t, D> cell;
      for (int d = 0; d < D; ++d) cell[d] = cells[d][lane];
      ASSERT_EQ(keys[lane], (hilbert_key<D, kBits>(cell))) << "D " << D << " lane " << lane;
    }
  }
}

TEST(SpaceFillingCurve, HilbertKeysInLanesEqualKeysOneCellAtATime) {
  std::mt19937 random(7);
  expect_lanes_match_one_cell_at_a_time<3, 20>(random);
  expect_lanes_match_one_cell_at_a_time<5, 12>(random);
  expect_lanes_match_one_cell_at_a_time<6, 10>(random);
  expect_lanes_match_one_cell_at_a_time<2, 4>(random);
}

// Small arrays sort in one block, large ones (200k) in blocks on several threads.
TEST(RadixSort, SortsStablyLikeAStableComparisonSort) {
  for (const std::uint32_t count : {5000u, 200000u})
  for (const std::uint64_t key_mask : {std::uint64_t{0xF}, std::uint64_t{0xFFFF0000FF}, ~std::uint64_t{0},
                                       (std::uint64_t{1} << 63) | 0xFFF}) {
    std::vector<SortEntry> entries;
    for (std::uint32_t i = 0; i < count; ++i) {
      entries.push_back({random_bits(i, 1, 0, RandomPurpose::benchmark) & key_mask, i / 100, i % 100});
    }
    std::vector<SortEntry> expected = entries, scratch;
    std::stable_sort(expected.begin(), expected.end(), [](const SortEntry& a, const SortEntry& b) { return a.key < b.key; });
    radix_sort_by_key(entries, scratch);
    for (std::size_t i = 0; i < entries.size(); ++i) {
      ASSERT_EQ(entries[i].key, expected[i].key);
      ASSERT_EQ(entries[i].batch, expected[i].batch);
      ASSERT_EQ(entries[i].ray, expected[i].ray);
    }
  }
}

TEST(Proxy, ClusteringMeetsItsTargetInsideTheBoundsAndWorksOnSoups) {
  for (const char* source : {"builtin:sphere:200k", "builtin:soup:200k", "builtin:terrain:200k"}) {
    const Scene scene = make_builtin_scene(source);
    const ClusterSimplification simplified = simplify_by_clustering(scene.mesh, 4000);
    EXPECT_NEAR(double(simplified.mesh.triangle_count()), 4000.0, 4000.0 * 0.2) << source;
    const Bounds3 original = scene.mesh.bounds(), proxy = simplified.mesh.bounds();
    const float slack = 0.02f * original.diagonal();
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_GE(proxy.lower[axis], original.lower[axis] - slack) << source;
      EXPECT_LE(proxy.upper[axis], original.upper[axis] + slack) << source;
    }
  }
}

TEST(Proxy, StandsInForTheSceneAndKeepsTheScenesBox) {
  const Scene scene = make_builtin_scene("builtin:sphere:200k");
  const auto accelerator = make_accelerator(scene.mesh, AcceleratorOptions{});
  ProxyOptions options;
  const Proxy proxy(scene.mesh, options, *accelerator);
  EXPECT_EQ(proxy.report().method, ProxyMethod::cluster);
  EXPECT_NEAR(double(proxy.report().triangles), 4000.0, 800.0);
  EXPECT_GT(proxy.report().quality.hit_overlap, 0.97);
  EXPECT_LT(proxy.report().quality.mean_distance_error, 0.01);
  ASSERT_TRUE(proxy.report().stochastic_quality.has_value());
  EXPECT_LT(proxy.report().stochastic_quality->hit_overlap, proxy.report().quality.hit_overlap);
  EXPECT_EQ(proxy.scene_bounds().lower, scene.mesh.bounds().lower);
  EXPECT_EQ(proxy.scene_bounds().upper, scene.mesh.bounds().upper);
  options.share = 0.0;
  EXPECT_THROW(Proxy(scene.mesh, options, *accelerator), SceneError);
}

TEST(Proxy, StochasticPruningKeepsItsShareAndTheExpectedArea) {
  const Scene scene = make_builtin_scene("builtin:fur:100k");
  const TriangleMesh pruned = simplify_stochastically(scene.mesh, 0.04);
  EXPECT_NEAR(double(pruned.triangle_count()), 0.04 * double(scene.mesh.triangle_count()), 400.0);
  const auto area = [](const TriangleMesh& mesh) {
    double sum = 0.0;
    for (const glm::uvec3& t : mesh.triangles) {
      sum += 0.5 * glm::length(glm::cross(glm::dvec3(mesh.positions[t.y] - mesh.positions[t.x]),
                                          glm::dvec3(mesh.positions[t.z] - mesh.positions[t.x])));
    }
    return sum;
  };
  EXPECT_NEAR(area(pruned) / area(scene.mesh), 1.0, 0.1);
}

using testing::CollectingOutput;

// [-1, 1]^3: the box the zsort tests' rays are scattered over.
Bounds3 cube_around_origin() {
  Bounds3 box;
  box.extend(glm::vec3(-1.0f));
  box.extend(glm::vec3(1.0f));
  return box;
}

TEST(ZSort, EmitsEveryRayOnceInKeyOrderWithShadowRaysLast) {
  BatchPool pool(64);
  const Bounds3 box = cube_around_origin();
  ZSortOptions options;
  options.heuristic = ReorderHeuristic::origin;
  options.curve = CurveKind::hilbert;
  options.buffer_rays = 1000;
  const ZSortStage zsort(options, box);
  std::uint32_t pixel = 0;
  for (int b = 0; b < 5; ++b) {
    Batch* batch = pool.acquire();
    batch->rays.count = 50;
    for (std::size_t i = 0; i < 50; ++i, ++pixel) {
      const UnitPair xy = unit_pair(random_bits(pixel, 0, 0, RandomPurpose::benchmark));
      batch->rays.set_geometry(i, glm::vec3(xy.first * 2 - 1, xy.second * 2 - 1, 0.0f), glm::vec3(0, 0, 1), 0, 1);
      batch->rays.pixel[i] = pixel;
      batch->rays.kind[i] = pixel % 7 == 0 ? RayKind::shadow : RayKind::bounce;
      batch->rays.flags[i] = ray_flags::alive;
    }
    EXPECT_FALSE(zsort.buffer(batch));
  }
  EXPECT_EQ(zsort.buffered_rays(), 250u);
  CollectingOutput out(pool);
  EXPECT_EQ(zsort.flush(out), 250u);
  EXPECT_EQ(zsort.buffered_rays(), 0u);
  ASSERT_EQ(out.emitted.size(), 4u);  // 64-ray batches
  std::set<std::uint32_t> pixels;
  std::uint64_t previous = 0;
  bool seen_shadow = false;
  for (Batch* batch : out.emitted) {
    for (std::size_t i = 0; i < batch->rays.count; ++i) {
      EXPECT_GE(batch->rays.sort_key[i], previous);
      previous = batch->rays.sort_key[i];
      const bool shadow = batch->rays.kind[i] == RayKind::shadow;
      EXPECT_FALSE(seen_shadow && !shadow);
      seen_shadow |= shadow;
      pixels.insert(batch->rays.pixel[i]);
    }
  }
  EXPECT_EQ(pixels.size(), 250u);
}

// A flush sorts the held batches' rays in place: every column (but the approximate hit,
// which only made the key) travels with its ray, the first held batches come out full and
// the rest go back to the pool, and no batch is taken from it (a second set of batches was
// a flush's peak). Arrivals of uneven counts make the places in and out differ.
TEST(ZSort, SortsInPlaceEveryColumnWithItsRay) {
  BatchPool pool(100);
  const Bounds3 box = cube_around_origin();
  ZSortOptions options;
  options.heuristic = ReorderHeuristic::origin_dir;
  options.curve = CurveKind::hilbert;
  options.buffer_rays = 100000;
  const ZSortStage zsort(options, box);
  std::uint32_t pixel = 0;
  std::vector<Batch*> arrivals;
  for (std::size_t count : {37, 100, 5, 64, 90, 1}) {
    Batch* batch = pool.acquire();
    for (std::size_t i = 0; i < count; ++i, ++pixel) {
      const UnitPair xy = unit_pair(random_bits(pixel, 0, 0, RandomPurpose::benchmark));
      const UnitPair zd = unit_pair(random_bits(pixel, 0, 1, RandomPurpose::benchmark));
      batch->rays.set_geometry(i, glm::vec3(xy.first, xy.second, zd.first) * 2.0f - 1.0f,
                               glm::normalize(glm::vec3(zd.second - 0.5f, xy.first - 0.5f, 0.3f)), 0.5f * pixel,
                               1000.0f + pixel);
      batch->rays.pixel[i] = pixel;
      batch->rays.sample[i] = 3 * pixel + 1;
      batch->rays.depth[i] = std::uint16_t(pixel % 9);
      batch->rays.kind[i] = RayKind(pixel % 4);
      batch->rays.throughput_r[i] = 0.25f * pixel;
      batch->rays.throughput_g[i] = 0.5f * pixel;
      batch->rays.throughput_b[i] = 2.0f * pixel;
      batch->rays.flags[i] = std::uint8_t(ray_flags::alive | (pixel % 2 ? ray_flags::continues : 0));
    }
    batch->rays.count = count;
    arrivals.push_back(batch);
    zsort.buffer(batch);
  }
  const std::uint32_t rays = pixel;
  const std::size_t batches_before = pool.allocated();
  CollectingOutput out(pool);
  ASSERT_EQ(zsort.flush(out), rays);
  EXPECT_EQ(pool.allocated(), batches_before);
  ASSERT_EQ(out.emitted.size(), 3u);  // 297 rays in batches of 100
  EXPECT_EQ(out.released, arrivals.size() - 3);
  std::set<std::uint32_t> pixels;
  std::uint64_t previous = 0;
  for (std::size_t b = 0; b < out.emitted.size(); ++b) {
    const RayBatch& sorted = out.emitted[b]->rays;
    EXPECT_EQ(out.emitted[b], arrivals[b]);
    EXPECT_EQ(sorted.count, b + 1 < out.emitted.size() ? 100u : rays - 200u);
    for (std::size_t i = 0; i < sorted.count; ++i) {
      const std::uint32_t p = sorted.pixel[i];
      EXPECT_GE(sorted.sort_key[i], previous);
      previous = sorted.sort_key[i];
      const UnitPair xy = unit_pair(random_bits(p, 0, 0, RandomPurpose::benchmark));
      const UnitPair zd = unit_pair(random_bits(p, 0, 1, RandomPurpose::benchmark));
      EXPECT_EQ(sorted.origin_x[i], xy.first * 2.0f - 1.0f);
      EXPECT_EQ(sorted.origin_z[i], zd.first * 2.0f - 1.0f);
      EXPECT_EQ(sorted.direction_x[i], glm::normalize(glm::vec3(zd.second - 0.5f, xy.first - 0.5f, 0.3f)).x);
      EXPECT_EQ(sorted.tmin[i], 0.5f * p);
      EXPECT_EQ(sorted.tmax[i], 1000.0f + p);
      EXPECT_EQ(sorted.sample[i], 3 * p + 1);
      EXPECT_EQ(sorted.depth[i], p % 9);
      EXPECT_EQ(sorted.kind[i], RayKind(p % 4));
      EXPECT_EQ(sorted.throughput_r[i], 0.25f * p);
      EXPECT_EQ(sorted.throughput_g[i], 0.5f * p);
      EXPECT_EQ(sorted.throughput_b[i], 2.0f * p);
      EXPECT_EQ(sorted.flags[i], std::uint8_t(ray_flags::alive | (p % 2 ? ray_flags::continues : 0)));
      pixels.insert(p);
    }
  }
  EXPECT_EQ(pixels.size(), rays);
}

// `ray_count` bounce rays in batches of 100 (in pixel order; the pool's batches must hold
// 100), scattered over the box [-1, 1]^3 in origin, direction and approximate hit.
std::vector<Batch*> scattered_arrivals(BatchPool& pool, std::uint32_t ray_count) {
  std::vector<Batch*> batches;
  for (std::uint32_t pixel = 0; pixel < ray_count; ++pixel) {
    if (pixel % 100 == 0) batches.push_back(pool.acquire());
    RayBatch& rays = batches.back()->rays;
    rays.enable_approx_hit();
    const std::size_t i = rays.count++;
    const UnitPair xy = unit_pair(random_bits(pixel, 0, 0, RandomPurpose::benchmark));
    const UnitPair zd = unit_pair(random_bits(pixel, 0, 1, RandomPurpose::benchmark));
    const UnitPair hit = unit_pair(random_bits(pixel, 0, 2, RandomPurpose::benchmark));
    const glm::vec3 direction = glm::normalize(glm::vec3(zd.second - 0.5f, xy.first - 0.5f, 0.3f));
    rays.set_geometry(i, glm::vec3(xy.first, xy.second, zd.first) * 2.0f - 1.0f, direction, 0.0f, 10.0f);
    rays.approx_hit_x[i] = hit.first * 2 - 1;
    rays.approx_hit_y[i] = hit.second * 2 - 1;
    rays.approx_hit_z[i] = zd.second * 2 - 1;
    rays.pixel[i] = pixel;
    rays.sample[i] = 7 * pixel;
    rays.kind[i] = RayKind::bounce;
    rays.flags[i] = ray_flags::alive;
  }
  return batches;
}

// Every heuristic changes the order zsort emits rays in (none keeps their arrival order),
// and emits them in non-decreasing key order: the image tests above cannot tell a sort that
// does nothing from one that works.
TEST(ZSort, EveryHeuristicReordersWhatNoneKeepsInArrivalOrder) {
  const Bounds3 box = cube_around_origin();
  constexpr std::uint32_t kRays = 400;
  const auto arrivals = [](BatchPool& pool) { return scattered_arrivals(pool, kRays); };
  std::map<std::string, std::vector<std::uint32_t>> orders;
  for (ReorderHeuristic heuristic : {ReorderHeuristic::none, ReorderHeuristic::origin, ReorderHeuristic::origin_dir,
                                    ReorderHeuristic::hph, ReorderHeuristic::hph_origin, ReorderHeuristic::hph_dir}) {
    for (CurveKind curve : {CurveKind::morton, CurveKind::hilbert}) {
      BatchPool pool(128);
      ZSortOptions options;
      options.heuristic = heuristic;
      options.curve = curve;
      options.buffer_rays = 100000;
      const ZSortStage zsort(options, box);
      for (Batch* batch : arrivals(pool)) zsort.buffer(batch);
      CollectingOutput out(pool);
      ASSERT_EQ(zsort.flush(out), kRays);
      std::vector<std::uint32_t>& order = orders[to_string(heuristic) + "/" + to_string(curve)];
      std::uint64_t previous = 0;
      for (const Batch* batch : out.emitted) {
        for (std::size_t i = 0; i < batch->rays.count; ++i) {
          order.push_back(batch->rays.pixel[i]);
          if (heuristic == ReorderHeuristic::none) continue;
          EXPECT_GE(batch->rays.sort_key[i], previous) << to_string(heuristic);
          previous = batch->rays.sort_key[i];
        }
      }
      ASSERT_EQ(order.size(), kRays);
    }
  }
  std::vector<std::uint32_t> arrival(kRays);
  for (std::uint32_t i = 0; i < kRays; ++i) arrival[i] = i;
  for (const auto& [name, order] : orders) {
    if (name.starts_with("none/")) {
      EXPECT_EQ(order, arrival) << name;
    } else {
      EXPECT_NE(order, arrival) << name;
      EXPECT_NE(order, orders.at(name.starts_with("hph") ? "origin/morton" : "hph/morton")) << name;
    }
  }
  // The two curves order the same keys' cells differently.
  EXPECT_NE(orders.at("hph/morton"), orders.at("hph/hilbert"));
}

// The disk buffer's runs merge into the order one in-core sort of the whole generation
// gives, every column travelling with its ray, for a hit-point heuristic as for origin.
TEST(ZSort, DiskRunsMergeIntoTheOrderOfOneInCoreSort) {
  const Bounds3 box = cube_around_origin();
  const auto order = [](const CollectingOutput& out) {
    std::vector<std::uint32_t> pixels;
    for (const Batch* batch : out.emitted) {
      for (std::size_t i = 0; i < batch->rays.count; ++i) {
        pixels.push_back(batch->rays.pixel[i]);
        EXPECT_EQ(batch->rays.sample[i], 7 * batch->rays.pixel[i]);
      }
    }
    return pixels;
  };
  for (ReorderHeuristic heuristic : {ReorderHeuristic::origin, ReorderHeuristic::hph}) {
    ZSortOptions options;
    options.heuristic = heuristic;
    options.buffer_rays = 1 << 20;
    BatchPool pool(128);  // scattered_arrivals fills batches of 100
    const ZSortStage memory(options, box);
    CollectingOutput in_core(pool);
    for (Batch* batch : scattered_arrivals(pool, 600)) EXPECT_EQ(memory.take(batch, in_core), 0u);
    EXPECT_EQ(memory.flush(in_core), 600u);

    options.buffer = RayBufferKind::disk;
    options.buffer_rays = 400;  // a run of the first four batches; the last two stay in core until the flush
    const ZSortStage disk(options, box);
    CollectingOutput spilled(pool);
    for (Batch* batch : scattered_arrivals(pool, 600)) EXPECT_EQ(disk.take(batch, spilled), 0u);
    EXPECT_EQ(disk.buffered_rays(), 600u);
    EXPECT_EQ(disk.spilled_rays(), 400u);
    EXPECT_EQ(disk.flush(spilled), 0u);
    EXPECT_TRUE(disk.draining());
    EXPECT_EQ(disk.spilled_rays(), 600u);  // the in-core part went to the last run
    std::size_t drained = 0;
    while (disk.draining()) drained += disk.drain(spilled, 64);
    EXPECT_EQ(drained, 600u);
    EXPECT_EQ(disk.spilled_rays(), 0u);
    EXPECT_EQ(order(spilled), order(in_core)) << to_string(heuristic);
    EXPECT_EQ(disk.spill().runs, 2u);
    EXPECT_GT(disk.spill().bytes_written, 600u * RayBatch::kBytesPerRay);
    // A spilled ray is its columns and key: its approximate hit stays behind (8-byte block
    // headers besides, at most 8 blocks of the pool's 128 rays).
    EXPECT_LE(disk.spill().bytes_written, 600u * (RayBatch::kBytesPerRay + RayBatch::kSortKeyBytesPerRay) + 8u * 8u);
    EXPECT_EQ(disk.spill().bytes_read, disk.spill().bytes_written);
  }
}

// A ray's key is its curve's index of the cell its point falls in (origin for `origin`,
// approximate hit for `hph`, 20 bits per axis); a shadow ray's is bit 63 and its index counted
// from the curve's far end, so that shadow rays sweep the world back the way bounce rays came.
TEST(ReorderKeys, AreTheCurveIndexOfTheQuantizedPoint) {
  const Bounds3 box = cube_around_origin();
  const std::vector<std::array<std::uint32_t, 3>> cells = {{3, 1000, 77}, {524287, 0, 1048575}, {1048575, 1, 65536}};
  RayBatch rays(4);
  rays.enable_approx_hit();
  rays.enable_sort_key();
  for (std::size_t i = 0; i < cells.size(); ++i) {
    glm::vec3 point;  // the cell's centre: exact in float at 20 bits over [-1, 1]
    for (int axis = 0; axis < 3; ++axis) point[axis] = -1.0f + (float(cells[i][axis]) + 0.5f) * (2.0f / 1048576.0f);
    rays.set_geometry(i, point, glm::vec3(0, 0, 1), 0.0f, 1.0f);
    rays.approx_hit_x[i] = point.x;
    rays.approx_hit_y[i] = point.y;
    rays.approx_hit_z[i] = point.z;
    rays.kind[i] = i == 2 ? RayKind::shadow : RayKind::bounce;
    rays.flags[i] = ray_flags::alive;
  }
  rays.count = cells.size();
  for (ReorderHeuristic heuristic : {ReorderHeuristic::origin, ReorderHeuristic::hph}) {
    for (CurveKind curve : {CurveKind::morton, CurveKind::hilbert}) {
      compute_sort_keys(rays, heuristic, curve, box);
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const std::uint64_t index =
            curve == CurveKind::morton ? morton_key<3, 20>(cells[i]) : hilbert_key<3, 20>(cells[i]);
        const std::uint64_t expected =
            rays.kind[i] == RayKind::shadow ? (std::uint64_t{1} << 63) | ((std::uint64_t{1} << 60) - 1 - index) : index;
        EXPECT_EQ(rays.sort_key[i], expected) << to_string(heuristic) << " " << to_string(curve) << " " << i;
      }
    }
  }
}

// Hilbert keys are made eight rays at a time: a batch of 13 (a full block and a tail) keys
// every ray as a batch of one ray keys it, for every heuristic.
TEST(ReorderKeys, HilbertKeysInBlocksEqualKeysRayByRay) {
  const Bounds3 box = cube_around_origin();
  std::mt19937 random(11);
  std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f);
  RayBatch rays(16), one(1);
  rays.count = 13;
  one.count = 1;
  for (RayBatch* batch : {&rays, &one}) batch->enable_approx_hit();
  for (std::size_t i = 0; i < rays.count; ++i) {
    const glm::vec3 origin(coordinate(random), coordinate(random), coordinate(random));
    const glm::vec3 direction = glm::normalize(glm::vec3(coordinate(random), coordinate(random), coordinate(random)));
    rays.set_geometry(i, origin, direction, 0.0f, 1.0f);
    rays.approx_hit_x[i] = coordinate(random);
    rays.approx_hit_y[i] = coordinate(random);
    rays.approx_hit_z[i] = coordinate(random);
    rays.kind[i] = i % 5 == 2 ? RayKind::shadow : RayKind::bounce;
    rays.flags[i] = ray_flags::alive;
  }
  for (ReorderHeuristic heuristic : {ReorderHeuristic::origin, ReorderHeuristic::origin_dir, ReorderHeuristic::hph,
                                     ReorderHeuristic::hph_origin, ReorderHeuristic::hph_dir}) {
    compute_sort_keys(rays, heuristic, CurveKind::hilbert, box);
    for (std::size_t i = 0; i < rays.count; ++i) {
      one.copy_ray(0, rays, i);
      compute_sort_keys(one, heuristic, CurveKind::hilbert, box);
      EXPECT_EQ(rays.sort_key[i], one.sort_key[0]) << to_string(heuristic) << " ray " << i;
    }
  }
}

// At a fixed budget on a fixed scene, hph cuts the simulated page faults of trace against
// none by a clear margin (1.86x when this test was written), single-threaded, so exact.
TEST(Reordering, HitPointHeuristicCutsPageFaultsAgainstNone) {
  Config config;
  for (const char* setting : {"scene.source=builtin:room:100k", "accel.type=bvh", "render.width=64", "render.height=48",
                              "render.spp=2", "render.threads=1", "memory.budget=10%", "memory.page_bytes=4096",
                              "proxy.accel=bvh"}) {
    config.set(setting);
  }
  const ReorderBenchReport report = run_reorder_bench(config, {ReorderHeuristic::none, ReorderHeuristic::hph});
  ASSERT_EQ(report.results.size(), 2u);
  const auto& none = report.results[0];
  const auto& hph = report.results[1];
  ASSERT_TRUE(none.page_faults.has_value() && hph.page_faults.has_value());
  EXPECT_GT(*none.page_faults, 0u);
  EXPECT_LT(double(*hph.page_faults), 0.75 * double(*none.page_faults));
  EXPECT_TRUE(hph.image_identical);
}

// Rounds: each heuristic rendered that many times in turn, one result each, the images
// compared across every round; no round is an error, as the command line says.
TEST(Reordering, BenchmarkRoundsReportOneRenderPerHeuristic) {
  Config config;
  for (const char* setting : {"scene.source=builtin:room:20k", "accel.type=bvh", "render.width=32", "render.height=24",
                              "render.spp=1", "render.threads=2", "render.max_depth=3", "proxy.accel=bvh"}) {
    config.set(setting);
  }
  const ReorderBenchReport report = run_reorder_bench(config, {ReorderHeuristic::none, ReorderHeuristic::hph}, 3);
  EXPECT_EQ(report.rounds, 3);
  ASSERT_EQ(report.results.size(), 2u);
  EXPECT_EQ(report.results[0].heuristic, "none");
  EXPECT_EQ(report.results[1].heuristic, "hph");
  for (const ReorderBenchResult& result : report.results) {
    EXPECT_TRUE(result.image_identical) << result.heuristic;
    EXPECT_GT(result.render_seconds, 0.0);
  }
  EXPECT_EQ(to_json(report)["rounds"], 3);
  EXPECT_NE(to_table(report).find("the median of 3 rounds"), std::string::npos);
  EXPECT_THROW(run_reorder_bench(config, {ReorderHeuristic::none}, 0), ConfigError);
}

// `paths`, the paper's renderer without its reordering module (one path at a time, the
// megakernel), is a row like a heuristic's: the same image and rays, its reads counted.
TEST(Reordering, BenchmarkRendersOnePathAtATimeAsARow) {
  Config config;
  for (const char* setting : {"scene.source=builtin:room:20k", "accel.type=bvh", "render.width=32", "render.height=24",
                              "render.spp=1", "render.threads=2", "render.max_depth=3", "proxy.accel=bvh",
                              "memory.budget=20%", "memory.page_bytes=4096"}) {
    config.set(setting);
  }
  const ReorderBenchReport report = run_reorder_bench(
      config, {ReorderBenchRow(ReorderHeuristic::none), ReorderBenchRow::paths_row(), parse_reorder_bench_row("hph")});
  ASSERT_EQ(report.results.size(), 3u);
  const ReorderBenchResult& none = report.results[0];
  const ReorderBenchResult& paths = report.results[1];
  EXPECT_EQ(paths.heuristic, "paths");
  EXPECT_EQ(report.results[2].heuristic, "hph");
  EXPECT_TRUE(paths.image_identical);
  EXPECT_EQ(paths.rays_traced, none.rays_traced);
  EXPECT_GT(paths.trace_seconds, 0.0);
  ASSERT_TRUE(paths.page_faults.has_value());
  EXPECT_GT(*paths.page_faults, 0u);
  EXPECT_EQ(parse_reorder_bench_row("paths").name(), "paths");
  EXPECT_THROW(parse_reorder_bench_row("pathz"), std::invalid_argument);
}

struct Rendered {
  RenderOutput output;
  std::uint64_t approx_in = 0, approx_out = 0, traced = 0;
};

Rendered render(const Scene& scene, const Proxy* proxy, const std::vector<std::string>& settings) {
  Config config;
  for (const char* setting : {"render.width=40", "render.height=30", "render.spp=2", "render.max_depth=4",
                              "render.batch_size=256", "render.rays_in_flight=4096", "reorder.buffer_rays=3000"}) {
    config.set(setting);
  }
  for (const std::string& setting : settings) config.set(setting);
  const RenderPlan plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, plan.accelerator);
  const LightSampler lights(scene);
  Rendered rendered;
  rendered.output = render_image(plan, World{scene, *accelerator, lights, proxy}, resolve_camera(plan.camera, scene));
  for (const StageStats& stage : rendered.output.run.stages) {
    if (stage.name == "approx_hit") {
      rendered.approx_in = stage.rays_in;
      rendered.approx_out = stage.rays_out;
    }
    if (stage.name == "trace") rendered.traced = stage.rays_in;
  }
  return rendered;
}

TEST(Reordering, ImageIsBitIdenticalForEveryHeuristicAndCurve) {
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const auto accelerator = make_accelerator(scene.mesh, AcceleratorOptions{});
  const Proxy proxy(scene.mesh, ProxyOptions{}, *accelerator);
  const Rendered reference = render(scene, nullptr, {"render.threads=1"});
  double sum = 0.0;
  for (float value : reference.output.image) sum += value;
  EXPECT_GT(sum, 0.0);
  for (const char* heuristic : {"origin", "origin_dir", "hph", "hph_origin", "hph_dir"}) {
    for (const char* curve : {"morton", "hilbert"}) {
      const Rendered other = render(scene, &proxy, {std::string("reorder.heuristic=") + heuristic,
                                                    std::string("reorder.curve=") + curve, "render.threads=2",
                                                    curve[0] == 'm' ? "reorder.sort=radix" : "reorder.sort=parallel"});
      EXPECT_TRUE(other.output.image == reference.output.image) << heuristic << " " << curve;
      ASSERT_EQ(other.output.hit_rates.size(), reference.output.hit_rates.size());
      for (std::size_t d = 0; d < other.output.hit_rates.size(); ++d) {
        EXPECT_EQ(other.output.hit_rates[d].rays, reference.output.hit_rates[d].rays);
        EXPECT_EQ(other.output.hit_rates[d].hits, reference.output.hit_rates[d].hits);
      }
    }
  }
}

TEST(Reordering, ApproxHitRetiresRaysMissingTheSceneBoxWithTheirSkyLight) {
  const Scene scene = make_builtin_scene("builtin:sphere:5000");  // a white sky all around
  const auto accelerator = make_accelerator(scene.mesh, AcceleratorOptions{});
  const Proxy proxy(scene.mesh, ProxyOptions{}, *accelerator);
  const Rendered plain = render(scene, nullptr, {});
  const Rendered ordered = render(scene, &proxy, {"reorder.heuristic=hph"});
  EXPECT_TRUE(ordered.output.image == plain.output.image);
  EXPECT_LT(ordered.approx_out, ordered.approx_in);  // camera rays past the sphere, escaping bounces
  EXPECT_EQ(ordered.traced, ordered.approx_out);
  EXPECT_EQ(plain.traced - ordered.traced, ordered.approx_in - ordered.approx_out);
  for (std::size_t d = 0; d < plain.output.hit_rates.size(); ++d) {
    EXPECT_EQ(ordered.output.hit_rates[d].rays, plain.output.hit_rates[d].rays) << d;
    EXPECT_EQ(ordered.output.hit_rates[d].hits, plain.output.hit_rates[d].hits) << d;
  }
}

TEST(Reordering, ChainsFollowTheHeuristicAndBadChainsAreErrors) {
  Config config;
  EXPECT_EQ(plan_render(config).stages, (std::vector<std::string>{"generate", "trace", "shade", "spawn"}));
  config.set("reorder.heuristic=origin");
  EXPECT_EQ(plan_render(config).stages, (std::vector<std::string>{"generate", "zsort", "trace", "shade", "spawn"}));
  config.set("reorder.heuristic=hph_dir");
  EXPECT_EQ(plan_render(config).stages,
            (std::vector<std::string>{"generate", "approx_hit", "zsort", "trace", "shade", "spawn"}));
  EXPECT_TRUE(plan_render(config).needs_proxy());
  config.set("reorder.buffer_bytes=88000000");
  EXPECT_EQ(plan_render(config).reorder.buffer_rays, 88000000u / ZSortStage::kBytesPerBufferedRay);
  config.set("pipeline.stages=generate,zsort,trace,shade,spawn");
  EXPECT_THROW(plan_render(config), ConfigError);  // hph_dir without approx_hit
  config.set("pipeline.stages=generate,zsort,approx_hit,trace,shade,spawn");
  EXPECT_THROW(plan_render(config), ConfigError);
  config.set("pipeline.stages=generate,trace,zsort,shade,spawn");
  EXPECT_THROW(plan_render(config), ConfigError);
  EXPECT_THROW(config.set("reorder.heuristic=random"), ConfigError);
  EXPECT_THROW(config.set("reorder.curve=peano"), ConfigError);
  EXPECT_THROW(config.set("proxy.share=0"), ConfigError);
}

}  // namespace
}  // namespace wavetrace
