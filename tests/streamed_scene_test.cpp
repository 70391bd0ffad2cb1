// Builtin scenes made a range at a time: every range of every shape is the whole shape's
// triangles to the bit, and a streamed scene describes the same scene as the assembled one.
#include <gtest/gtest.h>

#include <algorithm>

#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/material_runs.hpp"
#include "wavetrace/scene/shapes.hpp"
#include "wavetrace/scene/triangle_source.hpp"

namespace wavetrace {
namespace {

// Triangle t of `part` has the same corner positions, in the same order, as triangle
// first + t of `whole`.
void expect_same_triangles(const TriangleMesh& whole, std::size_t first, const TriangleMesh& part, const std::string& label) {
  ASSERT_LE(first + part.triangle_count(), whole.triangle_count()) << label;
  for (std::size_t t = 0; t < part.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(part.positions[part.triangles[t][k]], whole.positions[whole.triangles[first + t][k]])
          << label << " triangle " << first + t << " corner " << k;
    }
  }
}

TEST(ShapeGenerator, AnyRangeIsTheWholeShapesTrianglesToTheBit) {
  const glm::vec3 offset(0.25f, -1.0f, 3.0f);
  std::vector<std::pair<std::string, std::unique_ptr<ShapeGenerator>>> shapes;
  shapes.emplace_back("sphere", displaced_sphere_shape(20000, glm::vec3(1.0f), 0.5f, 3));
  // 148,842 vertex keys: a range's keys fall in several blocks of 2^16, the edge vertices' and its face's.
  shapes.emplace_back("large sphere", displaced_sphere_shape(300000, glm::vec3(1.0f), 0.5f, 4));
  shapes.emplace_back("soup", soup_shape(5000, 1));
  shapes.emplace_back("terrain", terrain_shape(20000, 3.0f, 0.4f, 2));
  shapes.emplace_back("strands", strands_shape(24000, 0.5f, 0.3f, 0.004f, 1));
  shapes.emplace_back("shell", room_shell_shape(glm::vec3(-4, 0, -4), glm::vec3(4, 3.5f, 4), 8000));
  shapes.emplace_back("quad", quad_shape(glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1)));
  for (const auto& [name, shape] : shapes) {
    const TriangleMesh whole = generate_mesh(*shape, offset);
    ASSERT_EQ(whole.triangle_count(), shape->triangle_count()) << name;
    EXPECT_EQ(whole.vertex_count(), shape->distinct_vertices()) << name;
    const Bounds3 bounds = generated_bounds(*shape, offset);
    EXPECT_EQ(bounds.lower, whole.bounds().lower) << name;
    EXPECT_EQ(bounds.upper, whole.bounds().upper) << name;
    const std::size_t total = shape->triangle_count();
    for (const std::size_t pieces : {std::size_t{1}, std::size_t{3}, std::size_t{7}}) {
      std::size_t vertices = 0;
      for (std::size_t k = 0; k < pieces; ++k) {
        const std::size_t first = total * k / pieces, count = total * (k + 1) / pieces - first;
        const TriangleMesh part = generate_range(*shape, first, count, offset);
        expect_same_triangles(whole, first, part, name + " in " + std::to_string(pieces));
        // The range's vertices are its distinct corner keys in ascending order, as a world
        // file stores them.
        std::vector<std::uint64_t> keys(3 * count);
        shape->corners(first, count, keys.data());
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
        ASSERT_EQ(part.vertex_count(), keys.size()) << name << " in " << pieces;
        for (std::size_t v = 0; v < keys.size(); ++v) {
          ASSERT_EQ(part.positions[v], shape->position(keys[v]) + offset) << name << " in " << pieces << " vertex " << v;
        }
        if (shape->material_count() > 1) {
          ASSERT_EQ(part.material_of_triangle.size(), count);
          for (std::size_t t = 0; t < count; ++t) ASSERT_EQ(part.material_of_triangle[t], whole.material_of_triangle[first + t]);
        }
        vertices += part.vertex_count();
      }
      // Pieces share only the vertices along their cuts.
      EXPECT_GE(vertices, whole.vertex_count()) << name;
    }
  }
}

// Bounds over a known box skip the positions their shape's bound puts inside it, and give the
// known box extended by every vertex all the same, whether the box cuts through the shape near
// its surface, holds it whole or misses it.
TEST(ShapeGenerator, BoundsBeyondAKnownBoxAreEveryVertexsBounds) {
  const glm::vec3 offset(0.25f, -1.0f, 3.0f);
  for (const std::uint32_t seed : {3u, 11u}) {
    const auto sphere = displaced_sphere_shape(30000, glm::vec3(1.0f), 0.5f, seed);
    const Bounds3 whole = generated_bounds(*sphere, offset);
    const glm::vec3 center = (whole.lower + whole.upper) * 0.5f, half = whole.extent() * 0.5f;
    for (const float scale : {0.8f, 0.97f, 0.999f, 1.0f, 1.5f}) {
      for (const glm::vec3 shift : {glm::vec3(0.0f), glm::vec3(0.1f, -0.05f, 0.0f), glm::vec3(3.0f)}) {
        const Bounds3 known{center + shift - half * scale, center + shift + half * scale};
        Bounds3 expected = known, skipping = known;
        expected.extend(whole);
        skipping.extend(generated_bounds(*sphere, offset, &known));
        EXPECT_EQ(skipping.lower, expected.lower) << "seed " << seed << " scale " << scale;
        EXPECT_EQ(skipping.upper, expected.upper) << "seed " << seed << " scale " << scale;
      }
    }
  }
}

TEST(ShapeGenerator, StrandsOfAChunkGrowFromOnePatchOfTheSphere) {
  // The chunked build relies on runs of a shape being spatially compact.
  const auto strands = strands_shape(240000, 1.0f, 0.1f, 0.004f, 1);
  const std::size_t tenth = strands->triangle_count() / 100;
  const Bounds3 patch = generate_range(*strands, 50 * tenth, tenth).bounds();
  const Bounds3 all = generate_mesh(*strands).bounds();
  const glm::vec3 share = patch.extent() / all.extent();
  EXPECT_LT(share.x * share.y * share.z, 0.05f) << "1% of the strands spans " << share.x << " x " << share.y << " x " << share.z;
}

TEST(ProceduralScene, StreamedDescribesTheSameSceneAsAssembled) {
  for (const char* source : {"builtin:room:60k", "builtin:default:20k", "builtin:stadium:5000", "builtin:fur:20k"}) {
    const Scene assembled = make_builtin_scene(source);
    const Scene streamed = make_builtin_scene(source, true);
    ASSERT_TRUE(streamed.streamed() && !assembled.streamed()) << source;
    EXPECT_TRUE(streamed.mesh.triangles.empty()) << source;
    EXPECT_EQ(streamed.triangle_count, assembled.triangle_count) << source;
    EXPECT_EQ(streamed.vertex_count, assembled.vertex_count) << source;
    EXPECT_EQ(streamed.bounds.lower, assembled.bounds.lower) << source;
    EXPECT_EQ(streamed.bounds.upper, assembled.bounds.upper) << source;
    for (std::size_t t = 0; t < assembled.triangle_count; t += 7) {
      ASSERT_EQ(streamed.material_runs.material(t), assembled.mesh.material(t)) << source << " triangle " << t;
      ASSERT_EQ(assembled.material_runs.material(t), assembled.mesh.material(t)) << source << " triangle " << t;
    }
    EXPECT_LE(streamed.material_runs.run_count(), 16u) << source;
    const std::size_t third = streamed.triangle_count / 3;
    expect_same_triangles(assembled.mesh, third, streamed.stream->extract(third, third), source);
    // The light sampler generates only the emissive objects of a streamed scene.
    EXPECT_EQ(LightSampler(streamed).count(), LightSampler(assembled).count()) << source;
  }
}

TEST(MaterialRuns, LookUpEveryTriangleOfTheirList) {
  const std::vector<std::uint32_t> list = {3, 3, 3, 1, 1, 0, 2, 2, 2, 2, 5};
  const MaterialRuns runs = MaterialRuns::from_triangles(list, list.size());
  EXPECT_EQ(runs.run_count(), 5u);
  for (std::size_t t = 0; t < list.size(); ++t) EXPECT_EQ(runs.material(t), list[t]) << t;
  EXPECT_EQ(runs.material(1000), 5u);
  EXPECT_EQ(MaterialRuns::from_triangles({}, 10).material(7), 0u);
  MaterialRuns appended;
  appended.append(10, 4);
  EXPECT_THROW(appended.append(5, 1), std::logic_error);
  EXPECT_EQ(appended.material(3), 0u);
  EXPECT_EQ(appended.material(std::uint64_t{5} << 32), 4u);  // ids past 2^32
}

}  // namespace
}  // namespace wavetrace
