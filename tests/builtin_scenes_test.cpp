// Procedural scenes: triangle counts, closedness where promised, orientation, determinism.
#include <cstring>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/morton.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/mesh_report.hpp"
#include "wavetrace/scene/noise.hpp"
#include "wavetrace/scene/shape_generator.hpp"
#include "wavetrace/scene/shapes.hpp"
#include "wavetrace/scene/subdivide.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

using testing::signed_volume;

TEST(BuiltinScenes, SphereCountsFollowTheIcosphereLattice) {
  EXPECT_EQ(make_builtin_scene("builtin:sphere:20").mesh.triangle_count(), 20u);
  const Scene sphere = make_builtin_scene("builtin:sphere:100k");
  const std::size_t n = 71;  // round(sqrt(100000 / 20))
  EXPECT_EQ(sphere.mesh.triangle_count(), 20 * n * n);
  EXPECT_EQ(sphere.mesh.vertex_count(), 10 * n * n + 2);
}

TEST(BuiltinScenes, SphereIsClosedManifoldAndFacesOutward) {
  for (const char* source : {"builtin:sphere:20", "builtin:sphere:80", "builtin:sphere:50k"}) {
    const Scene sphere = make_builtin_scene(source);
    const MeshReport report = analyze_mesh(sphere.mesh);
    EXPECT_TRUE(report.closed()) << source;
    EXPECT_EQ(report.connected_components, 1u) << source;
    EXPECT_EQ(report.degenerate_triangles, 0u) << source;
    EXPECT_GT(signed_volume(sphere.mesh), 2.0) << source;  // about 4/3 pi for radius ~1
  }
}

// Every triangle's corners are neighbours on the lattice: a vertex id mapped back to the
// wrong lattice row or column would put a corner far across its face. On the unit sphere a
// lattice edge is at most the icosahedron's edge (1.0515) over n, stretched by at most
// 1 / 0.7947 (the faces' inradius) when projected.
TEST(BuiltinScenes, SphereVerticesLieOnTheLatticeTheirIdsName) {
  for (const std::size_t n : {3u, 4u, 5u, 8u, 37u, 211u}) {
    const auto shape = smooth_sphere_shape(20 * n * n, glm::vec3(0.0f), 1.0f);
    ASSERT_EQ(shape->triangle_count(), 20 * n * n);
    const float longest = 1.0515f / 0.7947f / float(n) * 1.01f;
    std::vector<std::uint64_t> corners(3 * shape->triangle_count());
    shape->corners(0, shape->triangle_count(), corners.data());
    std::size_t too_long = 0;
    for (std::size_t t = 0; t < shape->triangle_count(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 a = shape->position(corners[3 * t + k]), b = shape->position(corners[3 * t + (k + 1) % 3]);
        if (!(glm::distance(a, b) <= longest) || glm::distance(a, b) < 0.1f / float(n)) ++too_long;
      }
    }
    EXPECT_EQ(too_long, 0u) << "n = " << n;
  }
}

// The fractal sum in SIMD lanes is the scalar sum to the bit: in lattice order (the cached
// cells), at random, across cell boundaries and negative coordinates, with the seed and the
// octave count changing between calls.
TEST(Noise, FractalSumInLanesIsTheScalarSum) {
  std::uint64_t state = 12345;
  const auto next_unit = [&] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return float(state >> 40) / float(1 << 24);
  };
  std::size_t differing = 0, compared = 0;
  const auto compare = [&](const glm::vec3& point, int octaves, std::uint32_t seed) {
    const float lanes = fractal_noise(point, octaves, seed), scalar = fractal_noise_scalar(point, octaves, seed);
    ++compared;
    if (std::memcmp(&lanes, &scalar, sizeof(float)) != 0) ++differing;
  };
  for (int octaves = 1; octaves <= 9; ++octaves) {
    for (std::uint32_t seed : {0u, 7u, 4242u}) {
      for (int i = 0; i < 2000; ++i) {  // a lattice walk: neighbouring points share cells
        compare(glm::vec3(-1.3f + 0.0011f * float(i), 0.37f, 0.25f * float(i % 7)), octaves, seed);
      }
      for (int i = 0; i < 2000; ++i) {
        const glm::vec3 point(next_unit() * 40.0f - 20.0f, next_unit() * 6.0f - 3.0f, next_unit() * 400.0f - 200.0f);
        compare(point, octaves, seed);
        compare(point, octaves == 1 ? 8 : octaves - 1, seed + 1);  // another shape in between
      }
      compare(glm::vec3(0.0f), octaves, seed);
      compare(glm::vec3(-0.0f, 1.0f, -2.0f), octaves, seed);
    }
  }
  EXPECT_EQ(differing, 0u) << "of " << compared;
}

TEST(BuiltinScenes, SoupSharesNoVertex) {
  const Scene soup = make_builtin_scene("builtin:soup:2000");
  const MeshReport report = analyze_mesh(soup.mesh);
  EXPECT_EQ(report.connected_components, soup.mesh.triangle_count());
  EXPECT_EQ(report.boundary_edges, 3 * soup.mesh.triangle_count());
  EXPECT_EQ(soup.mesh.triangle_count(), make_builtin_scene("builtin:sphere:2000").mesh.triangle_count());
}

TEST(BuiltinScenes, TerrainIsOneOpenSheet) {
  const Scene terrain = make_builtin_scene("builtin:terrain:20000");
  const MeshReport report = analyze_mesh(terrain.mesh);
  EXPECT_EQ(terrain.mesh.triangle_count(), 2u * 100 * 100);
  EXPECT_EQ(report.connected_components, 1u);
  EXPECT_EQ(report.boundary_edges, 4u * 100);
  EXPECT_EQ(report.non_manifold_edges, 0u);
}

TEST(BuiltinScenes, StadiumIsASmallSphereInAHugeClosedBox) {
  const Scene stadium = make_builtin_scene("builtin:stadium:10k");
  const MeshReport report = analyze_mesh(stadium.mesh);
  EXPECT_TRUE(report.closed());
  EXPECT_EQ(report.connected_components, 2u);
  EXPECT_GT(report.bounds.extent().x, 900.0f);
  EXPECT_GT(signed_volume(stadium.mesh), -1e9 * 1.01);
  EXPECT_LT(signed_volume(stadium.mesh), 0.0);  // the box faces inward
}

TEST(BuiltinScenes, FurIsManyDisconnectedStrands) {
  const Scene fur = make_builtin_scene("builtin:fur:24000");
  const MeshReport report = analyze_mesh(fur.mesh);
  EXPECT_GT(report.connected_components, 800u);
  EXPECT_EQ(report.degenerate_triangles, 0u);
}

TEST(BuiltinScenes, DefaultHasALightAndACamera) {
  const Scene scene = make_builtin_scene("builtin:default");
  EXPECT_TRUE(scene.camera.has_value());
  bool emissive = false;
  for (std::size_t t = 0; t < scene.mesh.triangle_count(); ++t) emissive |= scene.materials[scene.mesh.material(t)].emissive();
  EXPECT_TRUE(emissive);
}

TEST(BuiltinScenes, GenerationIsDeterministic) {
  const Scene a = make_builtin_scene("builtin:fur:5000");
  const Scene b = make_builtin_scene("builtin:fur:5000");
  ASSERT_EQ(a.mesh.vertex_count(), b.mesh.vertex_count());
  for (std::size_t i = 0; i < a.mesh.vertex_count(); ++i) ASSERT_EQ(a.mesh.positions[i], b.mesh.positions[i]);
  for (std::size_t t = 0; t < a.mesh.triangle_count(); ++t) ASSERT_EQ(a.mesh.triangles[t], b.mesh.triangles[t]);
}

TEST(BuiltinScenes, BadNamesAndCountsAreErrors) {
  EXPECT_THROW(make_builtin_scene("builtin:teapot"), SceneError);
  EXPECT_THROW(make_builtin_scene("builtin:sphere:lots"), SceneError);
  EXPECT_THROW(make_builtin_scene("builtin:sphere:0"), SceneError);
  EXPECT_THROW(make_builtin_scene("builtin:sphere:-5"), SceneError);
  EXPECT_EQ(parse_triangle_count("8M", "x"), 8000000u);
  EXPECT_EQ(parse_triangle_count("250k", "x"), 250000u);
  EXPECT_EQ(parse_triangle_count("1.5M", "x"), 1500000u);
}

TEST(Subdivision, LoopQuadruplesAndKeepsClosed) {
  const Scene sphere = make_builtin_scene("builtin:sphere:320");
  const SubdivisionResult once = loop_subdivide(sphere.mesh, 1);
  const SubdivisionResult twice = loop_subdivide(sphere.mesh, 2);
  EXPECT_EQ(once.mesh.triangle_count(), 4 * sphere.mesh.triangle_count());
  EXPECT_EQ(twice.mesh.triangle_count(), 16 * sphere.mesh.triangle_count());
  EXPECT_EQ(twice.non_manifold_faces_dropped, 0u);
  EXPECT_TRUE(analyze_mesh(twice.mesh).closed());
  EXPECT_GT(signed_volume(twice.mesh), 2.0);
}

// A subdivided surface is numbered along the Z-order curve of its triangles' centroids (10 bits
// an axis over the mesh's bounds), so that neighbours have near numbers: each step of OpenMesh's
// Loop appends three of a face's four children at the end of the mesh.
TEST(Subdivision, NumbersTheTrianglesAlongTheZCurve) {
  const SubdivisionResult twice = loop_subdivide(make_builtin_scene("builtin:sphere:320").mesh, 2);
  const TriangleMesh& mesh = twice.mesh;
  Bounds3 bounds;
  for (const glm::vec3& p : mesh.positions) bounds.extend(p);
  const glm::vec3 scale = 1024.0f / (bounds.upper - bounds.lower);
  std::uint64_t previous = 0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::vec3 centroid = (mesh.positions[tri.x] + mesh.positions[tri.y] + mesh.positions[tri.z]) / 3.0f;
    const glm::uvec3 cell = glm::uvec3(glm::clamp((centroid - bounds.lower) * scale, glm::vec3(0.0f), glm::vec3(1023.0f)));
    const std::uint64_t key = morton3d_encode(cell.x, cell.y, cell.z);
    ASSERT_GE(key, previous) << "triangle " << t;
    previous = key;
  }
}

TEST(Subdivision, SceneRequestSubdividesRealMeshes) {
  const Scene scene = load_scene({std::string(WAVETRACE_DATA_DIR) + "/bunny00.off", 1});
  EXPECT_EQ(scene.mesh.triangle_count(), 4u * 75408);
  EXPECT_EQ(scene.subdivision_levels, 1u);
  EXPECT_THROW(load_scene({"builtin:sphere:20", 9}), SceneError);
}

}  // namespace
}  // namespace wavetrace
