// The disk ray buffer (reorder.buffer = disk): runs on disk merged into the order one
// in-core sort gives, the same image as the memory buffer and as no reordering, and bad
// spill directories named.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "collecting_output.hpp"
#include "render_support.hpp"
#include "test_support.hpp"
#include "wavetrace/kernels/random.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/stages/zsort.hpp"

namespace wavetrace {
namespace {

// 300 rays in 6 batches of 50, scattered over the box, a seventh of them shadow rays.
std::vector<Batch*> arrivals(BatchPool& pool) {
  std::vector<Batch*> batches;
  std::uint32_t pixel = 0;
  for (int b = 0; b < 6; ++b) {
    Batch* batch = pool.acquire();
    batch->rays.count = 50;
    for (std::size_t i = 0; i < 50; ++i, ++pixel) {
      const UnitPair xy = unit_pair(random_bits(pixel, 0, 0, RandomPurpose::benchmark));
      batch->rays.set_geometry(i, glm::vec3(xy.first * 2 - 1, xy.second * 2 - 1, 0.0f), glm::vec3(0, 0, 1), 0, 1);
      batch->rays.pixel[i] = pixel;
      batch->rays.sample[i] = 7 * pixel;
      batch->rays.kind[i] = pixel % 7 == 0 ? RayKind::shadow : RayKind::bounce;
      batch->rays.flags[i] = ray_flags::alive;
    }
    batches.push_back(batch);
  }
  return batches;
}

std::vector<std::uint32_t> emitted_pixels(const testing::CollectingOutput& out) {
  std::vector<std::uint32_t> pixels;
  for (const Batch* batch : out.emitted) {
    for (std::size_t i = 0; i < batch->rays.count; ++i) {
      pixels.push_back(batch->rays.pixel[i]);
      EXPECT_EQ(batch->rays.sample[i], 7 * batch->rays.pixel[i]);  // every column travels with its ray
    }
  }
  return pixels;
}

TEST(DiskRayBuffer, RunsMergeIntoTheOrderOfOneInCoreSort) {
  Bounds3 box;
  box.extend(glm::vec3(-1.0f));
  box.extend(glm::vec3(1.0f));
  ZSortOptions options;
  options.heuristic = ReorderHeuristic::origin;
  options.buffer_rays = 1 << 20;
  BatchPool pool(64);
  const ZSortStage memory(options, box);
  testing::CollectingOutput in_core(pool);
  for (Batch* batch : arrivals(pool)) EXPECT_EQ(memory.take(batch, in_core), 0u);
  EXPECT_EQ(memory.flush(in_core), 300u);

  options.buffer = RayBufferKind::disk;
  options.buffer_rays = 200;  // a run of the first four batches; the last two stay in core until the flush
  const ZSortStage disk(options, box);
  testing::CollectingOutput spilled(pool);
  for (Batch* batch : arrivals(pool)) EXPECT_EQ(disk.take(batch, spilled), 0u);
  EXPECT_EQ(disk.buffered_rays(), 300u);
  EXPECT_EQ(disk.spilled_rays(), 200u);
  EXPECT_EQ(disk.flush(spilled), 0u);
  EXPECT_TRUE(disk.draining());
  EXPECT_EQ(disk.spilled_rays(), 300u);  // the in-core part went to the last run
  std::size_t drained = 0;
  while (disk.draining()) drained += disk.drain(spilled, 64);
  EXPECT_EQ(drained, 300u);
  EXPECT_EQ(disk.spilled_rays(), 0u);
  EXPECT_EQ(emitted_pixels(spilled), emitted_pixels(in_core));
  EXPECT_EQ(disk.spill().runs, 2u);
  EXPECT_GT(disk.spill().bytes_written, 300u * RayBatch::kBytesPerRay);
  EXPECT_EQ(disk.spill().bytes_read, disk.spill().bytes_written);
}

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
  const std::string command = std::string("sh -c \"trap '' XFSZ; ulimit -f 64; exec ") + WAVETRACE_BINARY + " " +
                              render + "\" 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[4096];
  while (std::size_t read = std::fread(buffer, 1, sizeof buffer, pipe)) output.append(buffer, read);
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << output;
  EXPECT_NE(output.find("writing"), std::string::npos) << output;
  EXPECT_NE(output.find("of rays failed: File too large"), std::string::npos) << output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace wavetrace
