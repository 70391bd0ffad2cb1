// Ray-Strips: the byte layout and its size formula, both stripifiers' coverage, agreement
// with robust Embree (hits, t, barycentrics in the mesh's corner order) for single rays
// and packets, no leaks, the soup case's memory, and option errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>

#include "wavetrace/accel/raystrips/ray_strip_format.hpp"
#include "wavetrace/accel/raystrips/raystrips_accelerator.hpp"
#include "wavetrace/accel/raystrips/strip_encode.hpp"
#include "wavetrace/accel/raystrips/strip_traversal.hpp"
#include "wavetrace/accel/raystrips/stripify.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/config.hpp"
#include "accel_agreement.hpp"

namespace wavetrace {

// ctest names the stripifier rather than printing its bytes (found by ADL in wavetrace).
void PrintTo(StripifierKind kind, std::ostream* out) { *out << to_string(kind); }

namespace {

using namespace ray_strip;

TEST(RayStripFormat, SizeOfAStripOfNTrianglesFollowsTheFormula) {
  // 12-byte header, 3 bytes per node (ceil(n/2) - 1 of them above 14 triangles, none at or
  // below), indices and records, each aligned to its width, the whole to 4 bytes.
  EXPECT_EQ(strip_layout(1, kShortIndices | kShortRecords).size, 12u + 3 * 2 + 1 * 2 + 0);  // 20
  EXPECT_EQ(strip_layout(2, kShortIndices | kShortRecords).size, 24u);  // 12 + 8 + 4
  EXPECT_EQ(strip_layout(5, kShortIndices | kShortRecords).size, 36u);  // 12, +14 = 26, +10 = 36
  EXPECT_EQ(strip_layout(5, kByteIndices | kShortRecords).size, 32u);   // 12, +7 = 19 -> 20, +10 = 30 -> 32
  EXPECT_EQ(strip_layout(5, 0).size, 60u);                              // 12, +28 = 40, +20 = 60
  EXPECT_EQ(strip_layout(14, kByteIndices | kShortRecords).size, 56u);  // 12, +16 = 28, +28 = 56
  EXPECT_EQ(strip_layout(15, kByteIndices | kShortRecords).size, 80u);  // 12 + 21 = 33, +17 = 50, +30 = 80
  EXPECT_EQ(strip_layout(100, kShortIndices).size, 764u);   // 12 + 147 = 159 -> 160, +204 = 364, +400 = 764
  for (std::uint32_t n = 1; n <= 2000; ++n) {
    for (const std::uint8_t widths : {0, 1, 2, 3, 4, 6}) {
      const std::size_t w = (widths & kByteIndices) ? 1 : (widths & kShortIndices) ? 2 : 4;
      const std::size_t v = (widths & kShortRecords) ? 2 : 4;
      const std::size_t nodes = n > 14 ? (n + 1) / 2 - 1 : 0;
      std::size_t size = 12 + 3 * nodes;
      size = (size + w - 1) / w * w + w * (n + 2);
      size = (size + v - 1) / v * v + v * n;
      size = (size + 3) / 4 * 4;
      ASSERT_EQ(strip_layout(n, widths).size, size) << n << " triangles, widths " << int(widths);
      ASSERT_LE(strip_layout(n, widths).size, 12 + 1.5 * n + w * (n + 2) + v * n + 6);
      ASSERT_EQ(node_count(n), nodes);
    }
  }
}

TEST(RayStripTraversal, EveryIndexWidthFindsTheHitsOfTheWatertightTest) {
  // One strip of 20 triangles (so it has a tree) over a bent 2 x 11 quad row, its vertices
  // spaced 1, 300 and 5000 ids apart so that it is stored with 8-, 16- and 32-bit indices: the
  // gathered runs find, for every ray, the triangle and t the watertight test finds alone,
  // bit for bit the same at every width.
  std::vector<std::pair<std::uint32_t, float>> first_answers;
  for (const std::uint32_t spacing : {1u, 300u, 5000u}) {
    TriangleMesh mesh;
    mesh.positions.assign(22 * spacing, glm::vec3(0.0f));
    for (int column = 0; column < 11; ++column) {
      for (int row = 0; row < 2; ++row) {
        mesh.positions[(2 * column + row) * spacing] = {float(column), float(row), 0.3f * std::sin(float(column))};
      }
    }
    for (std::uint32_t k = 0; k < 20; ++k) mesh.triangles.emplace_back(k * spacing, (k + 1) * spacing, (k + 2) * spacing);
    std::vector<std::uint32_t> all(20);
    for (std::uint32_t t = 0; t < 20; ++t) all[t] = t;
    const std::vector<TriangleStrip> strips = stripify(mesh, all, StripifierKind::dual_path, kMaxTriangles);
    ASSERT_EQ(strips.size(), 1u);
    std::vector<std::uint32_t> identity(mesh.vertex_count());
    for (std::uint32_t v = 0; v < identity.size(); ++v) identity[v] = v;
    const StripEncoding encoding = choose_encoding(strips[0], identity);
    const std::uint8_t expected_width = spacing == 1 ? kByteIndices : spacing == 300 ? kShortIndices : 0;
    ASSERT_EQ(encoding.widths & (kByteIndices | kShortIndices), expected_width) << spacing;
    const auto n = static_cast<std::uint32_t>(strips[0].triangles.size());
    ASSERT_TRUE(has_tree(n));
    std::vector<std::byte> buffer(encoding.size(n));
    Bounds3 frame;
    for (const std::uint32_t vertex : strips[0].vertices) frame.extend(mesh.positions[vertex]);
    encode_strip(strips[0], encoding, identity, mesh.positions, mesh, frame, buffer.data());
    const StripView view(buffer.data());

    std::vector<std::pair<std::uint32_t, float>> answers;
    std::uint32_t hits = 0;
    for (int i = 0; i < 4000; ++i) {
      // Rays from above and below at many slants, through the row and past its ends.
      const float u = -0.5f + 11.0f * float(i % 400) / 400.0f, v = -0.2f + 1.4f * float(i / 400) / 10.0f;
      const glm::vec3 origin(u + 0.7f * std::sin(float(i)), v, i % 2 ? 3.0f : -3.0f);
      const glm::vec3 direction = glm::vec3(u, v, 0.1f * std::cos(float(i))) - origin;
      const SingleRay single{origin, direction, 0.0f, 100.0f, make_box_ray(origin, direction),
                             make_watertight_ray(origin, direction)};
      TriangleHit nearest{std::numeric_limits<float>::infinity(), 0, 0};
      std::uint32_t expected = kNoTriangle;
      for (std::uint32_t t = 0; t < 20; ++t) {
        TriangleHit hit;
        const glm::uvec3& c = mesh.triangles[t];
        if (intersect_watertight(single.sheared, mesh.positions[c.x], mesh.positions[c.y], mesh.positions[c.z], 0.0f,
                                 nearest.t, hit) && hit.t < nearest.t) {
          nearest = hit;
          expected = t;
        }
      }
      StripRay ray(single);
      NullProbe probe;
      ray.traverse<false>(view, frame, mesh.positions.data(), 0.0f, 100.0f, 2, probe);
      const std::uint32_t found = ray.found() ? view.triangle(ray.hit.triangle) : kNoTriangle;
      ASSERT_EQ(found, expected) << "ray " << i << ", spacing " << spacing;
      if (found != kNoTriangle) {
        ++hits;
        EXPECT_NEAR(ray.hit.t, nearest.t, 1e-5f * nearest.t) << "ray " << i;
      }
      answers.emplace_back(found, ray.found() ? ray.hit.t : -1.0f);
    }
    EXPECT_GT(hits, 1000u);
    // Straight down onto the shared edges and vertices of the row (x a whole number): edge
    // functions exactly zero, which the run decides in double. Neither triangle may let the
    // ray through.
    for (int column = 1; column < 10; ++column) {
      for (const float v : {0.0f, 0.25f, 0.5f, 1.0f}) {
        const glm::vec3 origin(float(column), v, 5.0f), direction(0.0f, 0.0f, -1.0f);
        const SingleRay single{origin, direction, 0.0f, 100.0f, make_box_ray(origin, direction),
                               make_watertight_ray(origin, direction)};
        StripRay ray(single);
        NullProbe probe;
        ray.traverse<false>(view, frame, mesh.positions.data(), 0.0f, 100.0f, 2, probe);
        ASSERT_TRUE(ray.found()) << "through the edge at x = " << column << ", y = " << v << ", spacing " << spacing;
        EXPECT_FLOAT_EQ(ray.hit.t, 5.0f - 0.3f * std::sin(float(column)));
        answers.emplace_back(view.triangle(ray.hit.triangle), ray.hit.t);
      }
    }
    if (first_answers.empty()) {
      first_answers = answers;
    } else {
      EXPECT_EQ(answers, first_answers) << "spacing " << spacing;
    }
  }
}

#if WAVETRACE_SIXTEEN_LANES
TEST(RayStripTraversal, PackedStripsAnswerAsTheirRunsBitForBit) {
  // The bent quad row of 20 triangles cut into strips of 5, 5, 4 and 6 triangles (7, 7, 6 and
  // 8 vertices), packed first and third, second and fourth into sixteen lanes: the lane pairs
  // and triples across two strips span gaps in the row and must not count as edges or
  // triangles. The packed test
  // finds, for every ray, the hit the eight-lane runs find strip by strip: the same triangle,
  // its t and weights to the bit, also straight down onto the shared edges (exact zeros).
  if (runnable_kernel_isas().back() != KernelIsa::avx512) GTEST_SKIP() << "this CPU has no AVX-512";
  TriangleMesh mesh;
  for (int column = 0; column < 11; ++column) {
    for (int row = 0; row < 2; ++row) {
      mesh.positions.emplace_back(float(column), float(row), 0.3f * std::sin(float(column)));
    }
  }
  for (std::uint32_t k = 0; k < 20; ++k) mesh.triangles.emplace_back(k, k + 1, k + 2);
  std::vector<std::uint32_t> identity(mesh.vertex_count());
  for (std::uint32_t v = 0; v < identity.size(); ++v) identity[v] = v;
  std::vector<std::vector<std::byte>> buffers;
  for (const auto& [first, end] : {std::pair(0u, 5u), {5u, 10u}, {10u, 14u}, {14u, 20u}}) {
    std::vector<std::uint32_t> part;
    for (std::uint32_t t = first; t < end; ++t) part.push_back(t);
    const std::vector<TriangleStrip> strips = stripify(mesh, part, StripifierKind::dual_path, kMaxTriangles);
    ASSERT_EQ(strips.size(), 1u);
    const auto n = static_cast<std::uint32_t>(strips[0].triangles.size());
    ASSERT_FALSE(has_tree(n));
    const StripEncoding encoding = choose_encoding(strips[0], identity);
    Bounds3 frame;
    for (const std::uint32_t vertex : strips[0].vertices) frame.extend(mesh.positions[vertex]);
    buffers.emplace_back(encoding.size(n));
    encode_strip(strips[0], encoding, identity, mesh.positions, mesh, frame, buffers.back().data());
  }
  std::vector<PackedStrips> packs(2);
  for (std::size_t s = 0; s < buffers.size(); ++s) {
    const StripView view(buffers[s].data());
    ASSERT_TRUE(packs[s % 2].fits(view.triangles()));
    packs[s % 2].add(view);
  }
  ASSERT_EQ(packs[0].lanes, 13u);
  ASSERT_EQ(packs[1].lanes, 15u);
  const auto answer = [](const StripRay& ray) {
    std::uint32_t bits[4] = {};
    std::memcpy(&bits[0], &ray.hit.t, 4);
    for (int c = 0; c < 3; ++c) std::memcpy(&bits[c + 1], &ray.hit.weights[c], 4);
    const std::uint32_t triangle = ray.found() ? StripView(ray.hit.strip).triangle(ray.hit.triangle) : kNoTriangle;
    return std::tuple(triangle, bits[0], bits[1], bits[2], bits[3]);
  };
  std::uint32_t hits = 0, rays = 0;
  const auto compare = [&](const glm::vec3& origin, const glm::vec3& direction) {
    const SingleRay single{origin, direction, 0.0f, 100.0f, make_box_ray(origin, direction),
                           make_watertight_ray(origin, direction)};
    StripRay runs(single), packed(single);
    NullProbe probe;
    for (const std::vector<std::byte>& buffer : buffers) {
      const StripView view(buffer.data());
      runs.test_run<false>(view, mesh.positions.data(), 0, view.triangles(), probe);
    }
    for (const PackedStrips& pack : packs) packed.test_packed<false>(pack, mesh.positions.data());
    ++rays;
    hits += runs.found();
    return answer(runs) == answer(packed);
  };
  for (int i = 0; i < 4000; ++i) {
    const float u = -0.5f + 11.0f * float(i % 400) / 400.0f, v = -0.2f + 1.4f * float(i / 400) / 10.0f;
    const glm::vec3 origin(u + 0.7f * std::sin(float(i)), v, i % 2 ? 3.0f : -3.0f);
    ASSERT_TRUE(compare(origin, glm::vec3(u, v, 0.1f * std::cos(float(i))) - origin)) << "ray " << i;
  }
  for (int column = 0; column <= 10; ++column) {
    for (const float v : {0.0f, 0.25f, 0.5f, 1.0f}) {
      ASSERT_TRUE(compare({float(column), v, 5.0f}, {0.0f, 0.0f, -1.0f})) << "down at x = " << column << ", y = " << v;
    }
  }
  // Aimed at points of the row's edges from slanted origins: edge functions that round to
  // zero in float and not in double, which both tests redo in double.
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    const std::uint32_t k = i % 19;  // the edge triangle k shares with triangle k + 1
    const glm::vec3 a = mesh.positions[k + 1], b = mesh.positions[k + 2];
    const glm::vec3 on_edge = a + unit(random) * (b - a);
    const glm::vec3 origin = on_edge + glm::vec3(unit(random) - 0.5f, unit(random) - 0.5f, 1.0f) * 3.0f;
    ASSERT_TRUE(compare(origin, on_edge - origin)) << "aimed at edge " << k << ", ray " << i;
  }
  EXPECT_GT(hits, 1000u);
  EXPECT_EQ(rays, 24044u);
}
#endif

TEST(RayStripFormat, EncodedStripDecodesToItsVerticesTrianglesAndCorners) {
  // A fan-free strip over a 2 x 4 quad grid: vertices 0..9, triangles of both windings.
  TriangleMesh mesh;
  for (int row = 0; row < 2; ++row) {
    for (int column = 0; column < 5; ++column) mesh.positions.emplace_back(float(column), float(row), 0.1f * column);
  }
  const std::vector<std::uint32_t> order = {0, 5, 1, 6, 2, 7, 3, 8, 4, 9};  // the strip's vertices
  for (std::uint32_t k = 0; k < 8; ++k) {
    // Mesh triangles in a rotated corner order, so the corner codes are not trivial.
    mesh.triangles.emplace_back(order[k + 1], order[k + 2], order[k]);
  }
  std::vector<std::uint32_t> all(8);
  for (std::uint32_t t = 0; t < 8; ++t) all[t] = 7 - t;  // any order in
  const std::vector<TriangleStrip> strips = stripify(mesh, all, StripifierKind::dual_path, kMaxTriangles);
  std::vector<std::uint32_t> identity(mesh.vertex_count());
  for (std::uint32_t v = 0; v < identity.size(); ++v) identity[v] = v;
  std::size_t covered = 0;
  for (const TriangleStrip& strip : strips) {
    const StripEncoding encoding = choose_encoding(strip, identity);
    const auto n = static_cast<std::uint32_t>(strip.triangles.size());
    std::vector<std::byte> buffer(encoding.size(n) + 64, std::byte{0xAB});
    Bounds3 frame;  // the strip's own box, as a binary top leaf of one strip has
    for (const std::uint32_t vertex : strip.vertices) frame.extend(mesh.positions[vertex]);
    encode_strip(strip, encoding, identity, mesh.positions, mesh, frame, buffer.data());
    for (std::size_t i = encoding.size(n); i < buffer.size(); ++i) ASSERT_EQ(buffer[i], std::byte{0xAB}) << "wrote past the formula";
    const StripView view(buffer.data());
    ASSERT_EQ(view.triangles(), n);
    ASSERT_EQ(view.size(), encoding.size(n));
    for (std::uint32_t i = 0; i < n + 2; ++i) EXPECT_EQ(view.vertex(i), strip.vertices[i]);
    for (std::uint32_t k = 0; k < n; ++k) {
      ASSERT_EQ(view.triangle(k), strip.triangles[k]);
      const glm::uvec3& corners = mesh.triangles[strip.triangles[k]];
      EXPECT_EQ(view.vertex(k + view.corners(k) / 3), corners.y);
      EXPECT_EQ(view.vertex(k + view.corners(k) % 3), corners.z);
    }
    // The root's decoded planes bound its children: the lower child ends at or before
    // lower_child_max, the upper one starts at or after upper_child_min, each within a step.
    if (node_count(n) > 0) {
      const int axis = view.node_bits(0) & kAxisMask;
      ASSERT_LT(axis, 3);
      const SplitPlanes planes = decode_split(view.split_steps(0), frame, axis);
      float lower_max = -1e30f, upper_min = 1e30f;
      const std::uint32_t split_vertex = 2 * ((leaf_count(n) + 1) / 2);  // first child: vertices [0, split + 2)
      const bool reverse = (view.node_bits(0) & kReverse) != 0;
      for (std::uint32_t i = 0; i < n + 2; ++i) {
        const float coordinate = mesh.positions[view.vertex(i)][axis];
        const bool in_first = i < split_vertex + 2, in_second = i >= split_vertex;
        if ((in_first && !reverse) || (in_second && reverse)) {
          EXPECT_LE(coordinate, planes.lower_child_max) << i;
          lower_max = std::max(lower_max, coordinate);
        }
        if ((in_second && !reverse) || (in_first && reverse)) {
          EXPECT_GE(coordinate, planes.upper_child_min) << i;
          upper_min = std::min(upper_min, coordinate);
        }
      }
      EXPECT_LE(planes.lower_child_max - lower_max, split_step(frame, axis) * 1.001f);
      EXPECT_LE(upper_min - planes.upper_child_min, split_step(frame, axis) * 1.001f);
    }
    covered += n;
  }
  EXPECT_GE(covered, 8u);
  EXPECT_EQ(strips.size(), 1u) << "a 2 x 4 quad strip is one strip";
}

class Stripifiers : public ::testing::TestWithParam<StripifierKind> {};

TEST_P(Stripifiers, CoverEveryTriangleWithItsOwnCornersAndRespectTheLengthLimit) {
  for (const char* source : {"builtin:sphere:20k", "builtin:soup:2000", "builtin:room:20k"}) {
    const Scene scene = make_builtin_scene(source);
    std::vector<std::uint32_t> triangles(scene.mesh.triangle_count());
    for (std::uint32_t t = 0; t < triangles.size(); ++t) triangles[t] = t;
    const std::uint32_t limit = 40;
    const std::vector<TriangleStrip> strips = stripify(scene.mesh, triangles, GetParam(), limit);
    std::vector<int> seen(triangles.size(), 0);
    for (const TriangleStrip& strip : strips) {
      ASSERT_LE(strip.triangles.size(), limit);
      ASSERT_EQ(strip.vertices.size(), strip.triangles.size() + 2);
      for (std::size_t k = 0; k < strip.triangles.size(); ++k) {
        const std::uint32_t t = strip.triangles[k];
        if (t == kNoTriangle) continue;
        ++seen[t];
        std::multiset<std::uint32_t> strip_corners(strip.vertices.begin() + k, strip.vertices.begin() + k + 3);
        const glm::uvec3& c = scene.mesh.triangles[t];
        ASSERT_EQ(strip_corners, (std::multiset<std::uint32_t>{c.x, c.y, c.z})) << source << " strip triangle " << k;
      }
    }
    for (std::uint32_t t = 0; t < triangles.size(); ++t) ASSERT_GE(seen[t], 1) << source << " triangle " << t;
  }
}

INSTANTIATE_TEST_SUITE_P(All, Stripifiers,
                         ::testing::Values(StripifierKind::dual_path, StripifierKind::openmesh,
                                           StripifierKind::longest_of_three),
                         [](const auto& info) { return to_string(info.param); });

TEST(LongestOfThreeStripifier, MakesOpenMeshsStripsVertexForVertexWhereOpenMeshHoldsTheSubMesh) {
  // Sub-meshes as a raystrips build cuts them (runs of 256 triangles in the mesh's order), of
  // manifold pieces: OpenMesh refuses no face of them, so its strips are the algorithm's.
  std::size_t compared = 0, turns = 0;
  for (const char* source : {"builtin:sphere:20k", "builtin:room:20k"}) {
    const Scene scene = make_builtin_scene(source);
    for (std::uint32_t first = 0; first + 256 <= scene.mesh.triangle_count(); first += 4096) {
      std::vector<std::uint32_t> triangles(256);
      for (std::uint32_t k = 0; k < 256; ++k) triangles[k] = first + k;
      const std::vector<TriangleStrip> ours = stripify(scene.mesh, triangles, StripifierKind::longest_of_three, 1000);
      const std::vector<TriangleStrip> theirs = stripify(scene.mesh, triangles, StripifierKind::openmesh, 1000);
      ASSERT_EQ(ours.size(), theirs.size()) << source << " from triangle " << first;
      for (std::size_t s = 0; s < ours.size(); ++s) {
        ASSERT_EQ(ours[s].vertices, theirs[s].vertices) << source << " from triangle " << first << " strip " << s;
        ASSERT_EQ(ours[s].triangles, theirs[s].triangles) << source << " from triangle " << first << " strip " << s;
        turns += std::count(ours[s].triangles.begin(), ours[s].triangles.end(), kNoTriangle);
      }
      compared += ours.size();
    }
  }
  EXPECT_GT(compared, 20u);
  EXPECT_GT(turns, 0u) << "no strip began with a swap: the flip was not exercised";
}

TEST(LongestOfThreeStripifier, TreatsANonManifoldOrFlippedEdgeAsABoundary) {
  // Three triangles on the edge (0, 1), and a fourth wound against its neighbour across (1, 2)
  // (both run 1 -> 2).
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {1, 1, 0}};
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {1, 2, 5}};
  const std::vector<std::uint32_t> all = {0, 1, 2, 3};
  const std::vector<TriangleStrip> strips = stripify(mesh, all, StripifierKind::longest_of_three, 100);
  std::vector<int> seen(all.size(), 0);
  for (const TriangleStrip& strip : strips) {
    ASSERT_EQ(strip.vertices.size(), strip.triangles.size() + 2);
    for (const std::uint32_t t : strip.triangles) {
      if (t != kNoTriangle) ++seen[t];
    }
  }
  EXPECT_EQ(seen, std::vector<int>(all.size(), 1));
  // No edge is shared by exactly two triangles wound against each other, so none is crossed.
  EXPECT_EQ(strips.size(), all.size());
}


class RayStripsAgreesWithEmbree : public ::testing::TestWithParam<std::string> {};

TEST_P(RayStripsAgreesWithEmbree, OnAtLeast9999PerMyriadOfRaysWithTheMeshsBarycentrics) {
  const Scene scene = load_scene({GetParam(), 0});
  AcceleratorOptions robust;
  robust.embree.mode = EmbreeMode::robust;
  const auto reference = make_accelerator(scene.mesh, robust);
  for (const StripifierKind stripifier : {StripifierKind::openmesh, StripifierKind::dual_path}) {
    for (const std::uint32_t run : {2u, 6u, 16u}) {
      RayStripsOptions options;
      options.stripifier = stripifier;
      options.run_triangles = run;
      options.strips_per_leaf = run == 16 ? 4 : 1;
      options.submesh_triangles = run == 16 ? 1000 : 256;
      const auto strips = make_raystrips_accelerator(scene.mesh, options);
      for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
        for (const bool packets : {false, true}) {
          if (packets && kind != RaySetKind::primary) continue;
          const testing::Agreement result = testing::compare_on_rays(scene, *reference, *strips, kind, 8000,
                                                   1e-4f * scene.mesh.bounds().diagonal(), 1e-3f, packets);
          const std::string label = to_string(stripifier) + " run " + std::to_string(run) + " " + to_string(kind) +
                                    (packets ? " packets" : "");
          EXPECT_LE(double(result.hit_differs), 1e-4 * double(result.rays)) << label;
          EXPECT_LE(double(result.far_t), 1e-4 * double(result.rays)) << label;
          EXPECT_EQ(result.far_uv, 0u) << label;
          if (kind == RaySetKind::primary) {
            EXPECT_GT(result.same_primitive, result.rays / 50) << label;  // enough hits to judge u, v
          }
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, RayStripsAgreesWithEmbree,
                         ::testing::ValuesIn(testing::agreement_scenes("builtin:soup:20k")),
                         testing::agreement_scene_label);

// The 8-wide quantized top holds the same strips as the binary one, so every ray finds the
// same surface; distances agree to float rounding where coincident triangles (the fur's
// strands, the stadium's thin plates) are met in another order. A child box quantized too
// tightly would lose hits here.
TEST(RayStrips, WideTopFindsWhatTheBinaryTopFinds) {
  for (const char* source : {"builtin:sphere:30k", "builtin:soup:20k", "builtin:stadium:2000", "builtin:fur:30k"}) {
    const Scene scene = make_builtin_scene(source);
    for (const std::uint32_t strips_per_leaf : {1u, 4u}) {
      RayStripsOptions options;
      options.strips_per_leaf = strips_per_leaf;
      const auto binary = make_raystrips_accelerator(scene.mesh, options);
      options.width = 8;
      const auto wide = make_raystrips_accelerator(scene.mesh, options);
      for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
        const testing::Agreement result = testing::compare_on_rays(
            scene, *binary, *wide, kind, 4000, 1e-6f * scene.mesh.bounds().diagonal(), 1e-4f, kind == RaySetKind::primary);
        const std::string label = std::string(source) + " " + to_string(kind) + " strips/leaf " + std::to_string(strips_per_leaf);
        EXPECT_EQ(result.hit_differs, 0u) << label;
        EXPECT_EQ(result.far_t, 0u) << label;
        EXPECT_EQ(result.far_uv, 0u) << label;
      }
    }
  }
}

TEST(RayStrips, PacketsAnswerExactlyAsSingleRays) {
  const Scene scene = make_builtin_scene("builtin:sphere:30k");
  RayStripsOptions options;
  for (const std::uint32_t min_active : {1u, 2u, 4u}) {
    options.packet_min_active = min_active;
    const auto strips = make_raystrips_accelerator(scene.mesh, options);
    const RaySet rays = make_ray_set(RaySetKind::primary, scene, *strips, 20000);
    const auto single = trace_ray_set(*strips, rays, false);
    const auto packets = trace_ray_set(*strips, rays, true);
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(single[b]->primitive[i], packets[b]->primitive[i]) << "min_active " << min_active;
        ASSERT_EQ(single[b]->t[i], packets[b]->t[i]);
        ASSERT_EQ(single[b]->u[i], packets[b]->u[i]);
      }
    }
  }
}

TEST(RayStrips, NoRayEscapesClosedMeshes) {
  for (const char* source : {"builtin:sphere:200k", "builtin:room:50k"}) {
    const Scene scene = make_builtin_scene(source);
    const LeakReport report =
        run_leak_bench(scene,
                       {parse_accelerator_spec("raystrips", Config{}),
                        parse_accelerator_spec("raystrips:stripifier=dual_path:run_triangles=2", Config{}),
                        parse_accelerator_spec("raystrips:width=8", Config{})},
                       200000, 0);
    ASSERT_EQ(report.results.size(), 3u);
    for (const LeakResult& result : report.results) EXPECT_EQ(result.escaped, 0u) << source << " " << result.label;
  }
}

TEST(RayStrips, MemoryIsItsPartsAndTheSoupStaysNearAnIndexedTriangleList) {
  const Scene sphere = make_builtin_scene("builtin:sphere:50k");
  const auto strips = make_raystrips_accelerator(sphere.mesh, RayStripsOptions{});
  const MemoryReport memory = strips->memory();
  std::size_t span_bytes = 0;
  for (const auto& span : strips->memory_spans()) span_bytes += span.size();
  EXPECT_EQ(memory.total(), span_bytes);
  BvhOptions baseline;
  const auto bvh = make_bvh_accelerator(sphere.mesh, baseline);
  EXPECT_LT(memory.total() * 2, bvh->memory().total()) << "connected meshes: well under half the baseline";
  RayStripsOptions wide_top;
  wide_top.width = 8;
  const auto wide = make_raystrips_accelerator(sphere.mesh, wide_top);
  span_bytes = 0;
  for (const auto& span : wide->memory_spans()) span_bytes += span.size();
  EXPECT_EQ(wide->memory().total(), span_bytes);
  EXPECT_LT(wide->memory().hierarchy, memory.hierarchy) << "64-byte nodes of eight against 32-byte nodes of two";

  // A soup has no connectivity: every strip is one triangle (§6.2).
  const Scene soup = make_builtin_scene("builtin:soup:20k");
  const auto soup_strips = make_raystrips_accelerator(soup.mesh, RayStripsOptions{});
  EXPECT_NE(soup_strips->build_notes().find("100.00% of triangles in strips of one"), std::string::npos)
      << soup_strips->build_notes();
  const auto soup_bvh = make_bvh_accelerator(soup.mesh, baseline);
  EXPECT_LT(soup_strips->memory().total(), soup_bvh->memory().total() * 14 / 10);
  RayStripsOptions grouped;
  grouped.strips_per_leaf = 4;
  EXPECT_LT(make_raystrips_accelerator(soup.mesh, grouped)->memory().total(), soup_bvh->memory().total() * 11 / 10);
}

TEST(RayStrips, BadOptionsAreClearErrors) {
  const Scene scene = make_builtin_scene("builtin:sphere:2000");
  RayStripsOptions options;
  options.width = 4;
  EXPECT_THROW(make_raystrips_accelerator(scene.mesh, options), std::invalid_argument);
  EXPECT_THROW(parse_accelerator_spec("raystrips:width=3", Config{}), ConfigError);
  options = {};
  options.submesh_triangles = 1;
  EXPECT_THROW(make_raystrips_accelerator(scene.mesh, options), std::invalid_argument);
  options = {};
  options.run_triangles = 1;
  EXPECT_THROW(make_raystrips_accelerator(scene.mesh, options), std::invalid_argument);
  options = {};
  options.packet_min_active = 5;
  EXPECT_THROW(make_raystrips_accelerator(scene.mesh, options), std::invalid_argument);
  EXPECT_THROW(parse_accelerator_spec("raystrips:stripifier=stripe", Config{}), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("raystrips:submesh_triangles=70000", Config{}), ConfigError);
  EXPECT_THROW(parse_stripifier("stripe"), std::invalid_argument);
  EXPECT_THROW(make_raystrips_accelerator(TriangleMesh{}, RayStripsOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace wavetrace
