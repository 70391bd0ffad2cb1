// builtin:room: a closed shell around detailed objects, its leak test from inside, and the
// per-depth hit rates a render reports.
#include <gtest/gtest.h>

#include <fstream>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/mesh_report.hpp"
#include "wavetrace/scene/shapes.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "render_support.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

RenderOutput render(const Scene& scene, std::vector<std::string> settings) {
  settings.insert(settings.begin(), {"render.width=32", "render.height=24", "render.spp=2"});
  return testing::render_scene(scene, settings);
}

TEST(Room, ShellIsClosedManifoldFacesInwardAndNearItsCount) {
  const glm::vec3 lower(-4, 0, -4), upper(4, 3.5, 4);
  const TriangleMesh shell = generate_mesh(*room_shell_shape(lower, upper, 20000));
  const MeshReport report = analyze_mesh(shell);
  EXPECT_TRUE(report.closed());
  EXPECT_EQ(report.connected_components, 1u);
  EXPECT_NEAR(double(shell.triangle_count()), 20000.0, 2000.0);
  EXPECT_NEAR(testing::signed_volume(shell), -8.0 * 3.5 * 8.0, 1e-3);  // the whole box, facing inward
  ASSERT_EQ(shell.material_of_triangle.size(), shell.triangle_count());
  for (std::size_t t = 0; t < shell.triangle_count(); ++t) {
    const glm::vec3 a = shell.positions[shell.triangles[t].x];
    const glm::vec3 b = shell.positions[shell.triangles[t].y];
    const glm::vec3 c = shell.positions[shell.triangles[t].z];
    const std::uint32_t expected = (a.x == lower.x && b.x == lower.x && c.x == lower.x)   ? 0u
                                   : (a.x == upper.x && b.x == upper.x && c.x == upper.x) ? 1u
                                                                                          : 2u;
    ASSERT_EQ(shell.material_of_triangle[t], expected) << "triangle " << t;
  }
}

TEST(Room, HoldsItsObjectsInsideWithTheCameraAndAnEnclosure) {
  const Scene room = make_builtin_scene("builtin:room:200k");
  EXPECT_NEAR(double(room.mesh.triangle_count()), 200000.0, 10000.0);
  ASSERT_TRUE(room.enclosure.has_value());
  ASSERT_TRUE(room.camera.has_value());
  const Bounds3 bounds = room.mesh.bounds();
  EXPECT_EQ(bounds.lower, room.enclosure->lower);  // nothing pokes through the walls
  EXPECT_EQ(bounds.upper, room.enclosure->upper);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GT(room.camera->position[axis], room.enclosure->lower[axis]);
    EXPECT_LT(room.camera->position[axis], room.enclosure->upper[axis]);
  }
  EXPECT_EQ(LightSampler(room).count(), 2u);
  EXPECT_GE(room.materials.size(), 8u);
  const MeshReport report = analyze_mesh(room.mesh);
  EXPECT_FALSE(report.closed());  // the terrain, the strands and the light are open
  EXPECT_GT(report.connected_components, 1000u);  // the strands
  const Scene again = make_builtin_scene("builtin:room:200k");
  EXPECT_TRUE(again.mesh.positions == room.mesh.positions);
}

TEST(Room, LeakBenchShootsFromInsideTheEnclosure) {
  const Scene room = make_builtin_scene("builtin:room:20k");
  Config config;
  const LeakReport report = run_leak_bench(
      room, {parse_accelerator_spec("embree:mode=robust", config), parse_accelerator_spec("bvh", config)}, 20000, 2);
  EXPECT_TRUE(report.enclosure);
  EXPECT_EQ(report.inside_points, 4096u);
  ASSERT_EQ(report.results.size(), 2u);
  for (const LeakResult& result : report.results) EXPECT_EQ(result.escaped, 0u) << result.label;
  // An open scene without an enclosure is refused.
  EXPECT_THROW(run_leak_bench(make_builtin_scene("builtin:terrain:200"), {parse_accelerator_spec("bvh", config)}, 100, 1),
               std::runtime_error);
}

TEST(HitRates, BounceRaysHitInTheRoomAndCountsChainAcrossDepths) {
  const Scene room = make_builtin_scene("builtin:room:20k");
  const RenderOutput output = render(room, {"render.max_depth=4", "render.russian_roulette_depth=64"});
  ASSERT_EQ(output.hit_rates.size(), 5u);  // depths 0 to 4
  EXPECT_EQ(output.hit_rates[0].rays, 32u * 24 * 2);
  for (const DepthHitRate& rate : output.hit_rates) EXPECT_GE(rate.rate(), 0.9) << "depth " << rate.depth;
  // Without roulette every hit on a non-emitter continues, so a depth's rays are the hits
  // before it minus the paths that ended on the light.
  for (std::size_t d = 1; d < output.hit_rates.size(); ++d) {
    EXPECT_LE(output.hit_rates[d].rays, output.hit_rates[d - 1].hits);
    EXPECT_GE(output.hit_rates[d].rays, output.hit_rates[d - 1].hits * 95 / 100);
  }
}

TEST(HitRates, EqualHitsOfThePreviousDepthWhereNothingEmits) {
  const Scene sphere = make_builtin_scene("builtin:sphere:2000");
  const RenderOutput output = render(sphere, {"render.max_depth=3", "render.russian_roulette_depth=64"});
  ASSERT_GE(output.hit_rates.size(), 2u);
  EXPECT_GT(output.hit_rates[0].hits, 0u);
  EXPECT_LT(output.hit_rates[0].hits, output.hit_rates[0].rays);  // the sky around it
  for (std::size_t d = 1; d < output.hit_rates.size(); ++d) {
    EXPECT_EQ(output.hit_rates[d].rays, output.hit_rates[d - 1].hits) << "depth " << d;
  }
  EXPECT_LT(output.hit_rates[1].rate(), 0.2);  // a lone convex-ish sphere: bounces escape
}

TEST(HitRates, RenderStatsJsonListsThem) {
  const std::string stats = testing::write_temp_file("room_stats.json", "");
  const auto result = testing::run_wavetrace("render builtin:room:5000 --size 16x12 --spp 1 --stats " + stats +
                                             " --out " + testing::write_temp_file("room.exr", ""));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("hit rate by depth"), std::string::npos) << result.output;
  std::ifstream file(stats);
  const nlohmann::json json = nlohmann::json::parse(file);
  ASSERT_TRUE(json["hit_rates"].is_array());
  ASSERT_GE(json["hit_rates"].size(), 2u);
  EXPECT_EQ(json["hit_rates"][0]["depth"], 0);
  EXPECT_EQ(json["hit_rates"][0]["rays"], 16 * 12);
  EXPECT_GE(json["hit_rates"][1]["hit_rate"].get<double>(), 0.9);
}

}  // namespace
}  // namespace wavetrace
