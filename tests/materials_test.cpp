// Mirrors and glass: Fresnel and Snell in the scatter kernel, scene files and saved worlds
// that keep them, and renders with exact answers (the furnace's closed form, a mirror showing
// a light, glass that neither loses nor makes light under a uniform sky), bit-identical across
// threads, batch sizes and the megakernel.
#include <cmath>
#include <numeric>

#include <gtest/gtest.h>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/kernels/specular.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/scene/scene_file.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_file.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

constexpr std::uint32_t kWidth = 48, kHeight = 36;

std::vector<float> render(const Scene& scene, const std::vector<std::string>& settings) {
  Config config;
  config.set("render.width=" + std::to_string(kWidth));
  config.set("render.height=" + std::to_string(kHeight));
  config.set("render.spp=2");
  for (const std::string& setting : settings) config.set(setting);
  const RenderPlan plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, plan.accelerator);
  const LightSampler lights(scene);
  return render_image(plan, World{scene, *accelerator, lights}, resolve_camera(plan.camera, scene)).image;
}

double mean(const std::vector<float>& image) {
  return std::accumulate(image.begin(), image.end(), 0.0) / double(image.size());
}

TEST(SpecularKernel, GlassFollowsSnellAndFresnel) {
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  // Head on, glass of index 1.5 reflects ((n - 1) / (n + 1))^2 = 4%.
  EXPECT_NEAR(dielectric_reflectance(1.0f, 1.0f, 1.0f / 1.5f), 0.04f, 1e-6f);
  EXPECT_EQ(glass_scatter({0, -1, 0}, up, 1.5f, 0.039f).transmitted, false);
  EXPECT_EQ(glass_scatter({0, -1, 0}, up, 1.5f, 0.041f).transmitted, true);
  // At 45 degrees from outside: sin(t) = sin(45) / 1.5, bent toward the normal.
  const glm::vec3 incoming = glm::normalize(glm::vec3(1.0f, -1.0f, 0.0f));
  const SpecularScatter entering = glass_scatter(incoming, up, 1.5f, 0.99f);
  ASSERT_TRUE(entering.transmitted);
  EXPECT_NEAR(entering.direction.x, std::sqrt(0.5f) / 1.5f, 1e-6f);
  EXPECT_LT(entering.direction.y, 0.0f);
  EXPECT_NEAR(glm::length(entering.direction), 1.0f, 1e-6f);
  // Leaving along the reverse path retraces it (Helmholtz), with the same reflectance.
  const SpecularScatter leaving = glass_scatter(-entering.direction, up, 1.5f, 0.99f);
  ASSERT_TRUE(leaving.transmitted);
  EXPECT_NEAR(glm::dot(leaving.direction, -incoming), 1.0f, 1e-6f);
  // From inside past the critical angle (41.8 degrees for 1.5): always reflected, mirror-like.
  const glm::vec3 steep = glm::normalize(glm::vec3(1.0f, 0.8f, 0.0f));
  const SpecularScatter trapped = glass_scatter(steep, up, 1.5f, 0.999f);
  EXPECT_FALSE(trapped.transmitted);
  EXPECT_NEAR(trapped.direction.y, -steep.y, 1e-6f);
  // At grazing incidence everything is reflected.
  EXPECT_NEAR(dielectric_reflectance(0.0f, std::sqrt(1.0f - 1.0f / 2.25f), 1.0f / 1.5f), 1.0f, 1e-6f);
}

TEST(Materials, SceneFilesGiveMirrorsAndGlassTheirSettings) {
  const std::string path = testing::write_temp_file("specular.toml", R"(
[[object]]
mesh = "builtin:ball:80"
material = { type = "glass", ior = 1.33 }
[[object]]
mesh = "builtin:plane"
material = { type = "mirror", albedo = [0.9, 0.8, 0.7] }
[[object]]
mesh = "builtin:plane"
material = { albedo = 0.4, emission = 2 }
)");
  const Scene scene = load_scene_file(path);
  ASSERT_EQ(scene.materials.size(), 3u);
  EXPECT_EQ(scene.materials[0].surface, Surface::glass);
  EXPECT_FLOAT_EQ(scene.materials[0].ior, 1.33f);
  EXPECT_EQ(scene.materials[0].albedo, glm::vec3(1.0f)) << "untinted glass passes all light";
  EXPECT_EQ(scene.materials[1].surface, Surface::mirror);
  EXPECT_EQ(scene.materials[1].albedo, glm::vec3(0.9f, 0.8f, 0.7f));
  EXPECT_EQ(scene.materials[2].surface, Surface::diffuse);
  EXPECT_EQ(scene.materials[2].emission, glm::vec3(2.0f));
}

TEST(Materials, FurnaceRadianceIsEmissionOverOneMinusAlbedo) {
  // Every wall emits Le and reflects rho: L = Le / (1 - rho) everywhere, whatever the
  // tessellation. Depth 64 leaves rho^65 of it untraced.
  const Scene furnace = make_builtin_scene("builtin:furnace:2000");
  const std::vector<float> image = render(furnace, {"render.max_depth=64", "render.spp=8"});
  const double expected = kFurnaceEmission / (1.0 - kFurnaceAlbedo);
  EXPECT_NEAR(mean(image), expected, 0.01 * expected);
  // Without the roulette, what noise is left comes from the light samples over flat facets
  // (on a true sphere each would carry exactly rho Le).
  const std::vector<float> unrouletted = render(furnace, {"render.max_depth=40", "render.russian_roulette_depth=64"});
  EXPECT_NEAR(mean(unrouletted), expected, 0.002 * expected);
}

// A mirror at z = 0 facing a camera at z = 5; behind the camera an emitter faces the mirror.
Scene mirror_scene(Surface surface) {
  Scene scene;
  scene.name = "mirror";
  scene.mesh.positions = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0},
                          {-50, -50, 10}, {50, -50, 10}, {50, 50, 10}, {-50, 50, 10}};
  scene.mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}};
  scene.mesh.material_of_triangle = {0, 0, 1, 1};
  validate_and_clean(scene.mesh, "mirror");
  scene.materials = {Material{glm::vec3(0.5f, 0.25f, 1.0f), glm::vec3(0.0f), surface},
                     Material{glm::vec3(0.0f), glm::vec3(3.0f)}};
  scene.describe_mesh();
  scene.camera = Camera{glm::vec3(0, 0, 5), glm::vec3(0), glm::vec3(0, 1, 0), 30.0f};
  return scene;
}

TEST(Materials, AMirrorShowsTheLightTimesItsAlbedo) {
  const std::vector<float> image = render(mirror_scene(Surface::mirror), {});
  for (std::size_t pixel = 0; pixel < image.size() / 3; ++pixel) {
    ASSERT_FLOAT_EQ(image[3 * pixel + 0], 1.5f);
    ASSERT_FLOAT_EQ(image[3 * pixel + 1], 0.75f);
    ASSERT_FLOAT_EQ(image[3 * pixel + 2], 3.0f);
  }
  // The same surface diffuse sees the light only through its light samples: not that.
  EXPECT_FALSE(render(mirror_scene(Surface::diffuse), {}) == image);
}

TEST(Materials, GlassUnderAUniformSkyNeitherLosesNorMakesLight) {
  Scene scene = make_builtin_scene("builtin:ball:20000");
  scene.materials[0] = Material{glm::vec3(1.0f), glm::vec3(0.0f), Surface::glass, 1.5f};
  scene.background = glm::vec3(1.0f);
  scene.camera = Camera{glm::vec3(0, 0, 3.5f), glm::vec3(0), glm::vec3(0, 1, 0), 40.0f};
  const std::vector<std::string> untruncated = {"render.max_depth=64", "render.russian_roulette_depth=64"};
  // Every path ends in the sky with weight 1, but for the few that the facets trap by total
  // internal reflection past 64 bounces (physical for a faceted ball, not a smooth one).
  const std::vector<float> image = render(scene, untruncated);
  for (float value : image) ASSERT_LE(value, 1.0f + 1e-5f);
  EXPECT_GT(mean(image), 0.998);
  // Index 1 bends nothing and reflects nothing: every pixel exactly the sky.
  scene.materials[0].ior = 1.0f;
  for (float value : render(scene, untruncated)) ASSERT_NEAR(value, 1.0f, 1e-5f);
  scene.materials[0].ior = 1.5f;
  // Tinted, the centre (through the glass, refracted twice, or reflected once) is darker.
  scene.materials[0].albedo = glm::vec3(0.5f);
  const std::vector<float> tinted = render(scene, untruncated);
  const std::size_t centre = 3 * (kHeight / 2 * kWidth + kWidth / 2);
  EXPECT_LT(tinted[centre], 0.5f);
  EXPECT_FLOAT_EQ(tinted[0], 1.0f) << "the corner sees the sky";
}

TEST(Materials, ImagesWithMirrorsAndGlassAreIdenticalAcrossThreadsBatchesAndModes) {
  const Scene scene = load_scene({std::string(WAVETRACE_SOURCE_DIR) + "/scenes/caustic.toml", 0});
  const std::vector<float> reference = render(scene, {"render.threads=1", "render.batch_size=4096", "render.max_depth=6"});
  EXPECT_GT(mean(reference), 0.01);
  for (const std::vector<std::string>& variant : std::vector<std::vector<std::string>>{
           {"render.threads=2", "render.batch_size=64"},
           {"render.threads=2", "reorder.heuristic=origin_dir", "render.pixel_order=scanline"},
           {"render.threads=2", "pipeline.mode=megakernel"}}) {
    std::vector<std::string> settings = variant;
    settings.push_back("render.max_depth=6");
    EXPECT_TRUE(render(scene, settings) == reference) << "differs with " << variant[0] << " " << variant[1];
  }
}

TEST(Materials, SavedWorldsKeepMirrorsAndGlass) {
  const Scene scene = load_scene({std::string(WAVETRACE_SOURCE_DIR) + "/scenes/caustic.toml", 0});
  Config config;
  config.set("accel.type=bvh");
  const RenderPlan plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, plan.accelerator);
  const LightSampler lights(scene);
  const std::string path = testing::write_temp_file("specular.wtw", "");
  save_world(path, scene, lights, *accelerator, plan.accelerator.type, nullptr, config, {});
  const std::unique_ptr<LoadedWorld> loaded = load_world(path);
  ASSERT_EQ(loaded->scene.materials.size(), scene.materials.size());
  bool glass = false, mirror = false;
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    EXPECT_EQ(loaded->scene.materials[i].surface, scene.materials[i].surface);
    EXPECT_EQ(loaded->scene.materials[i].ior, scene.materials[i].ior);
    EXPECT_EQ(loaded->scene.materials[i].albedo, scene.materials[i].albedo);
    glass |= scene.materials[i].surface == Surface::glass;
    mirror |= scene.materials[i].surface == Surface::mirror;
  }
  EXPECT_TRUE(glass && mirror);
}

}  // namespace
}  // namespace wavetrace
