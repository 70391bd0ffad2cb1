// The disk ray buffer (reorder.buffer = disk) in whole renders: the same image as the memory
// buffer and as no reordering, and bad spill directories named. (Its merge order is tested
// with zsort's in reorder_test.cpp.)
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render_support.hpp"
#include "test_support.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/plan_render.hpp"
#include "wavetrace/stages/gather_spawn.hpp"
#include "wavetrace/stages/spawn.hpp"

namespace wavetrace {
namespace {

TEST(DiskRayBuffer, ImageIsBitIdenticalToTheMemoryBufferAndToNoReordering) {
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const std::vector<std::string> common = {"render.width=48", "render.height=32", "render.spp=2", "render.threads=2"};
  const auto with = [&](std::vector<std::string> more) {
    more.insert(more.end(), common.begin(), common.end());
    return testing::render_scene(scene, more);
  };
  const RenderOutput none = with({"reorder.heuristic=none"});
  const RenderOutput memory = with({"reorder.heuristic=hph"});
  // An in-core part of 1500 rays: every generation of 3072 camera rays spills.
  const RenderOutput disk = with({"reorder.heuristic=hph", "reorder.buffer=disk", "reorder.buffer_rays=1500"});
  EXPECT_TRUE(memory.image == none.image);
  EXPECT_TRUE(disk.image == none.image);
  bool spilled = false;
  for (const StageStats& stage : disk.run.stages) {
    if (stage.name != "zsort") continue;
    ASSERT_TRUE(stage.spill.has_value());
    spilled = stage.spill->runs >= 2 && stage.spill->bytes_read == stage.spill->bytes_written;
  }
  EXPECT_TRUE(spilled);
  const RenderOutput one_thread = with({"reorder.heuristic=hph_origin", "reorder.buffer=disk",
                                        "reorder.buffer_rays=1024", "render.threads=1"});
  EXPECT_TRUE(one_thread.image == none.image);
}

// The disk buffer's in-core part fills with camera rays, so the flight budget must leave room
// for it and for the rays each of its camera rays may become (the spawn stages' own count).
TEST(DiskRayBuffer, TheFlightBudgetHoldsTheInCorePartAndWhatItsRaysBecome) {
  const auto plan_with = [](std::vector<std::string> settings) {
    Config config;
    for (const std::string& setting : {"reorder.heuristic=hph", "reorder.buffer=disk", "reorder.buffer_rays=3000"}) {
      settings.push_back(setting);
    }
    for (const std::string& setting : settings) config.set(setting);
    return plan_render(config);
  };
  const RenderPlan path = plan_with({});
  const RenderPlan photon = plan_with({"render.integrator=photon", "photon.gather_rays=6"});
  EXPECT_EQ(rays_per_camera_ray(path), 2u);
  EXPECT_EQ(path.pipeline.rays_in_flight, 2u * 3000);
  EXPECT_EQ(rays_per_camera_ray(photon), 7u);
  EXPECT_EQ(photon.pipeline.rays_in_flight, 7u * 3000);

  const Scene scene = make_builtin_scene("builtin:room:20k");
  const auto accelerator = make_accelerator(scene.mesh, path.accelerator);
  const LightSampler lights(scene);
  const World world{scene, *accelerator, lights, nullptr};
  EXPECT_EQ(SpawnStage(world, path.rules).rays_out_per_ray(), rays_per_camera_ray(path));
  EXPECT_EQ(GatherSpawnStage(world, photon.rules, photon.photon.gather_rays).rays_out_per_ray(),
            rays_per_camera_ray(photon));

  try {
    plan_with({"render.rays_in_flight=5000"});
    ADD_FAILURE() << "a flight budget under the in-core part times 2 was accepted";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("render.rays_in_flight = 5000 is under the disk buffer's in-core part "
                                             "(3000 rays) times the 2 rays each camera ray may become"),
              std::string::npos)
        << error.what();
  }
}

// What the command says of a spill directory it cannot use, of a disk buffer without zsort,
// and of a disk that fills up during the render: an error naming the key or the directory,
// status 1, no image written as if complete.
TEST(DiskRayBuffer, BadSpillDirectoriesAndAFullDiskAreErrorsNamingThem) {
  const std::string out = testing::write_temp_file("spill_render.exr", "");
  std::remove(out.c_str());
  const std::string render = "render builtin:room:20k --size 64x48 --spp 2 --threads 2 --out " + out +
                             " --set reorder.heuristic=hph --set reorder.buffer=disk --set reorder.buffer_rays=2048";
  const auto missing = testing::run_wavetrace(render + " --set reorder.spill_dir=/nonexistent/spill");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("reorder.spill_dir = /nonexistent/spill: No such file or directory"), std::string::npos)
      << missing.output;
  const auto not_a_directory = testing::run_wavetrace(render + " --set reorder.spill_dir=/etc/hostname");
  EXPECT_EQ(not_a_directory.exit_code, 1);
  EXPECT_NE(not_a_directory.output.find("reorder.spill_dir = /etc/hostname: cannot create spill files there"),
            std::string::npos)
      << not_a_directory.output;
  const auto without_zsort = testing::run_wavetrace("render builtin:room:20k --size 8x8 --set reorder.buffer=disk");
  EXPECT_EQ(without_zsort.exit_code, 1);
  EXPECT_NE(without_zsort.output.find("reorder.buffer = disk is zsort's buffer"), std::string::npos)
      << without_zsort.output;
  EXPECT_FALSE(std::filesystem::exists(out));

  // A file size limit of 64 KiB stands in for a full disk: the runs' writes fail with EFBIG
  // (SIGXFSZ ignored, as a full disk gives ENOSPC without a signal).
  const auto [exit_code, output] = testing::run_wavetrace(render, "trap '' XFSZ; ulimit -f 64;");
  EXPECT_EQ(exit_code, 1) << output;
  EXPECT_NE(output.find("writing"), std::string::npos) << output;
  EXPECT_NE(output.find("of rays failed: File too large"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace wavetrace
