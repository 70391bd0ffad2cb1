// Photon mapping: the k-nearest irradiance estimate against known photon densities, the
// furnace's closed form, the caustic scene against the path tracer, and images that are the
// same for any thread count, batch size, pixel order and reordering heuristic.
#include <cmath>
#include <numeric>

#include <gtest/gtest.h>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/kernels/random.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/stages/photon_deposits.hpp"
#include "wavetrace/stages/photon_map.hpp"

namespace wavetrace {
namespace {

RenderOutput render(const Scene& scene, const std::vector<std::string>& settings) {
  Config config;
  config.set("render.width=40");
  config.set("render.height=30");
  config.set("render.spp=2");
  config.set("render.integrator=photon");
  for (const std::string& setting : settings) config.set(setting);
  const RenderPlan plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, plan.accelerator);
  const LightSampler lights(scene);
  std::unique_ptr<Proxy> proxy;
  if (plan.needs_proxy()) proxy = std::make_unique<Proxy>(scene.mesh, plan.proxy, *accelerator);
  return render_image(plan, World{scene, *accelerator, lights, proxy.get()}, resolve_camera(plan.camera, scene));
}

double mean(const std::vector<float>& image) {
  return std::accumulate(image.begin(), image.end(), 0.0) / double(image.size());
}

// Photons of power 1 on a jittered grid of the unit square in z = 0, `per_side` a side, facing +z.
PhotonArray square_of_photons(int per_side) {
  PhotonArray photons;
  for (int y = 0; y < per_side; ++y) {
    for (int x = 0; x < per_side; ++x) {
      const UnitPair u = unit_pair(random_bits(x, y, 0, RandomPurpose::benchmark));
      photons.push_back({glm::vec3((x + u.first) / per_side, (y + u.second) / per_side, 0.0f), glm::vec3(1.0f),
                         glm::vec3(0, 0, 1)});
    }
  }
  return photons;
}

TEST(PhotonMap, EstimatesTheDensityOfFluxFromTheNearestPhotons) {
  const PhotonMap map(square_of_photons(200));  // 40,000 photons of power 1 on a unit square
  const glm::vec3 centre(0.5f, 0.5f, 0.0f), up(0, 0, 1);
  // k photons within r: (k photons) / (pi r^2), about the density 40,000.
  const glm::vec3 estimate = map.irradiance(centre, up, 100, 1.0f);
  EXPECT_NEAR(estimate.x, 40000.0f, 0.15f * 40000.0f);
  EXPECT_EQ(estimate.x, estimate.z);
  // Fewer than k within the bound: the bound is the radius.
  const float bound = 0.01f;  // about 12.6 photons' area
  const glm::vec3 bounded = map.irradiance(centre, up, 100, bound);
  EXPECT_GT(bounded.x, 0.0f);
  EXPECT_NEAR(bounded.x, 40000.0f, 0.6f * 40000.0f);
  const float found = bounded.x * kPi * bound * bound;  // photons over the bound's disc
  EXPECT_NEAR(found, std::round(found), 1e-3f);
  EXPECT_GE(found, 3.0f);
  EXPECT_LT(found, 30.0f);
  // From the far side of the surface, nothing: each photon came from +z.
  EXPECT_EQ(map.irradiance(centre, -up, 100, 1.0f), glm::vec3(0.0f));
  // Out past the square's corner by more than the bound: nothing.
  EXPECT_EQ(map.irradiance(glm::vec3(3.0f), up, 100, 0.5f), glm::vec3(0.0f));
  EXPECT_EQ(PhotonMap({}).irradiance(centre, up, 100, 1.0f), glm::vec3(0.0f));
}

TEST(PhotonMap, PrecomputedIrradianceIsTheNearestPrecomputedEstimate) {
  PhotonMap map(square_of_photons(100));  // 10,000 photons
  EXPECT_FALSE(map.has_precomputed());
  map.precompute_irradiance(4, 50, 0.2f);
  EXPECT_EQ(map.precomputed_count(), 2500u);
  const glm::vec3 up(0, 0, 1), query(0.4f, 0.6f, 0.0f);
  // The nearest precomputed point's estimate: the full estimate there, not at the query.
  const Photon* closest = nullptr;
  for (std::size_t i = 0; i < map.size(); i += 4) {
    const Photon& photon = map.photons()[i];
    if (closest == nullptr || glm::length(photon.position - query) < glm::length(closest->position - query)) {
      closest = &photon;
    }
  }
  const glm::vec3 cached = map.precomputed_irradiance(query, up, 50, 0.2f);
  EXPECT_EQ(cached, map.irradiance(closest->position, closest->normal, 50, 0.2f));
  EXPECT_NE(cached, map.irradiance(query, up, 50, 0.2f));
  EXPECT_NEAR(cached.x, 10000.0f, 0.25f * 10000.0f);
  // Facing away from every photon: no precomputed point qualifies, and the full estimate is 0.
  EXPECT_EQ(map.precomputed_irradiance(query, -up, 50, 0.2f), glm::vec3(0.0f));
}

TEST(PhotonDeposits, MergeInKeyOrderWhateverThreadAddedThem) {
  PhotonDeposits deposits;
  deposits.add(PhotonDeposits::key(7, 1), Photon{glm::vec3(7.1f), glm::vec3(1), glm::vec3(0, 1, 0)}, false);
  deposits.add(PhotonDeposits::key(2, 0), Photon{glm::vec3(2.0f), glm::vec3(1), glm::vec3(0, 1, 0)}, true);
  deposits.add(PhotonDeposits::key(7, 0), Photon{glm::vec3(7.0f), glm::vec3(1), glm::vec3(0, 1, 0)}, true);
  const PhotonDeposits::Maps maps = deposits.take();
  ASSERT_EQ(maps.global.size(), 3u);
  EXPECT_EQ(maps.global[0].position.x, 2.0f);
  EXPECT_EQ(maps.global[1].position.x, 7.0f);
  EXPECT_EQ(maps.global[2].position.x, 7.1f);
  ASSERT_EQ(maps.caustic.size(), 2u);
  EXPECT_EQ(maps.caustic[1].position.x, 7.0f);
}

TEST(PhotonRender, FurnaceRadianceIsEmissionOverOneMinusAlbedo) {
  // Photons from every wall, bouncing with albedo 1/2: the global map's irradiance is
  // pi Le / (1 - rho) everywhere, and camera rays see Le + rho Le (light samples) + rho L.
  const Scene furnace = make_builtin_scene("builtin:furnace:2000");
  const RenderOutput output =
      render(furnace, {"render.max_depth=64", "render.spp=4", "photon.count=200000", "photon.gather_rays=4"});
  const double expected = kFurnaceEmission / (1.0 - kFurnaceAlbedo);
  EXPECT_NEAR(mean(output.image), expected, 0.01 * expected);
  ASSERT_TRUE(output.photons.has_value());
  EXPECT_EQ(output.photons->emitted, 200000u);
  // Every photon lands (nothing escapes a closed sphere), then half go on at each bounce.
  EXPECT_NEAR(double(output.photons->global_photons), 400000.0, 0.02 * 400000.0);
  EXPECT_EQ(output.photons->caustic_photons, 0u) << "no mirror or glass";
  EXPECT_EQ(output.photons->precomputed, 0u);
  // Gathering rays reading irradiance precomputed at every 4th photon instead.
  const RenderOutput cached = render(furnace, {"render.max_depth=64", "render.spp=4", "photon.count=200000",
                                               "photon.gather_rays=4", "photon.precompute=4"});
  EXPECT_NEAR(mean(cached.image), expected, 0.01 * expected);
  EXPECT_NEAR(double(cached.photons->precomputed), double(output.photons->global_photons) / 4, 1.0);
  EXPECT_FALSE(cached.image == output.image);
}

const Scene& caustic_scene() {
  static const Scene scene = load_scene({std::string(WAVETRACE_SOURCE_DIR) + "/scenes/caustic.toml", 0});
  return scene;
}

TEST(PhotonRender, ImageIsIdenticalForThreadsBatchSizesOrdersAndHeuristics) {
  const std::vector<std::string> base = {"photon.count=20000", "render.max_depth=6", "photon.gather_rays=3"};
  const auto with = [&](std::vector<std::string> more) {
    more.insert(more.end(), base.begin(), base.end());
    return more;
  };
  const RenderOutput reference = render(caustic_scene(), with({"render.threads=1", "render.batch_size=4096"}));
  EXPECT_GT(mean(reference.image), 0.01);
  EXPECT_GT(reference.photons->caustic_photons, 0u);
  for (const std::vector<std::string>& variant : std::vector<std::vector<std::string>>{
           {"render.threads=2", "render.batch_size=64"},
           {"render.threads=2", "render.pixel_order=scanline", "reorder.heuristic=origin_dir"},
           {"render.threads=2", "reorder.heuristic=hph"}}) {
    const RenderOutput other = render(caustic_scene(), with(variant));
    EXPECT_TRUE(other.image == reference.image) << "differs with " << variant[0] << " " << variant[1];
    EXPECT_EQ(other.photons->global_photons, reference.photons->global_photons);
  }
}

TEST(PhotonRender, CausticSceneAgreesWithThePathTracer) {
  // The same image by both integrators. The path tracer finds the caustic only by bounce rays
  // that happen to reach the light through the glass, so it needs thousands of samples; the
  // photon map's estimate is biased by its radius (bench photons charts it), so a small one.
  const std::vector<std::string> common = {"render.max_depth=8", "render.width=40", "render.height=30"};
  std::vector<std::string> path = common;
  path.insert(path.end(), {"render.integrator=path", "render.spp=4096"});
  std::vector<std::string> photon = common;
  photon.insert(photon.end(), {"render.spp=64", "photon.count=1000000", "photon.radius=0.01", "photon.gather_rays=1"});
  const std::vector<float> traced = render(caustic_scene(), path).image;
  const std::vector<float> mapped = render(caustic_scene(), photon).image;
  EXPECT_NEAR(mean(mapped), mean(traced), 0.02 * mean(traced));
  // The caustic and the ball's shadow around it (rows 18-23, columns 12-21 of 40 x 30).
  const auto region_mean = [](const std::vector<float>& image) {
    double sum = 0.0;
    int count = 0;
    for (int y = 18; y <= 23; ++y) {
      for (int x = 12; x <= 21; ++x) {
        for (int c = 0; c < 3; ++c, ++count) sum += image[(y * 40 + x) * 3 + c];
      }
    }
    return sum / count;
  };
  EXPECT_NEAR(region_mean(mapped), region_mean(traced), 0.1 * region_mean(traced));
}

TEST(PhotonRender, PlansThatCannotRunArePlainErrors) {
  Config config;
  config.set("render.integrator=photon");
  config.set("pipeline.mode=megakernel");
  EXPECT_THROW(plan_render(config), ConfigError);
  Config chain;
  chain.set("render.integrator=photon");
  chain.set("pipeline.stages=[generate, trace, shade]");
  EXPECT_THROW(plan_render(chain), ConfigError);
  // Maps past the memory available: refused before a photon is traced.
  try {
    render(make_builtin_scene("builtin:furnace:200"), {"photon.count=4000000000"});
    ADD_FAILURE() << "no error for 4G photons";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("photon.count = 4000000000: its photon maps would need"), std::string::npos)
        << error.what();
  }
  Config unknown;
  EXPECT_THROW(
      {
        unknown.set("render.integrator=bidirectional");
        plan_render(unknown);
      },
      ConfigError);
}

}  // namespace
}  // namespace wavetrace
