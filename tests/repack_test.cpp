// repack: small batches gathered into full ones of one ray kind, large ones passed on, every
// ray emitted once with its columns; and a chain with repack renders the same image.
#include <set>

#include <gtest/gtest.h>

#include "collecting_output.hpp"
#include "render_support.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/stages/repack.hpp"

namespace wavetrace {
namespace {

Batch* batch_of(BatchPool& pool, std::size_t count, RayKind kind, std::uint32_t& next_pixel) {
  Batch* batch = pool.acquire();
  for (std::size_t i = 0; i < count; ++i) {
    batch->rays.set_geometry(i, glm::vec3(float(next_pixel)), glm::vec3(0, 0, 1), 0.0f, 1.0f);
    batch->rays.pixel[i] = next_pixel++;
    batch->rays.kind[i] = kind;
    batch->rays.flags[i] = ray_flags::alive;
  }
  batch->rays.count = count;
  return batch;
}

TEST(Repack, GathersSmallBatchesByKindAndPassesLargeOnes) {
  BatchPool pool(64);
  testing::CollectingOutput out(pool);
  const RepackStage repack(32);
  std::uint32_t pixel = 0;
  std::size_t emitted = 0;
  emitted += repack.take(batch_of(pool, 40, RayKind::bounce, pixel), out);  // passes
  EXPECT_EQ(emitted, 40u);
  for (int b = 0; b < 5; ++b) {
    emitted += repack.take(batch_of(pool, 20, RayKind::bounce, pixel), out);
    emitted += repack.take(batch_of(pool, 10, RayKind::shadow, pixel), out);
  }
  // 100 small bounce rays fill one batch of 64 (36 held); 50 shadow rays are all held.
  EXPECT_EQ(emitted, 40u + 64u);
  EXPECT_EQ(repack.buffered_rays(), 36u + 50u);
  EXPECT_EQ(out.released, 10u);  // the small batches, once copied
  emitted += repack.flush(out);
  EXPECT_EQ(repack.buffered_rays(), 0u);
  EXPECT_EQ(emitted, std::size_t(pixel));
  EXPECT_EQ(repack.flush(out), 0u);

  std::set<std::uint32_t> seen;
  for (const Batch* batch : out.emitted) {
    const RayBatch& rays = batch->rays;
    for (std::size_t i = 0; i < rays.count; ++i) {
      EXPECT_EQ(rays.kind[i], rays.kind[0]);  // one kind per batch
      EXPECT_EQ(rays.origin_x[i], float(rays.pixel[i]));  // the ray's columns came with it
      EXPECT_TRUE(seen.insert(rays.pixel[i]).second);
    }
  }
  EXPECT_EQ(seen.size(), std::size_t(pixel));
}

TEST(Repack, ChainWithRepackRendersTheSameImage) {
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const std::vector<std::string> common = {"render.width=40", "render.height=30", "render.spp=2", "render.threads=2",
                                           "render.batch_size=64"};
  std::vector<std::string> repacked = common;
  repacked.push_back(R"(pipeline.stages=["generate", "repack", "trace", "shade", "spawn"])");
  const RenderOutput plain = testing::render_scene(scene, common);
  const RenderOutput with_repack = testing::render_scene(scene, repacked);
  EXPECT_TRUE(plain.image == with_repack.image);
  ASSERT_EQ(with_repack.run.stages.size(), 5u);
  EXPECT_EQ(with_repack.run.stages[1].name, "repack");
  EXPECT_EQ(with_repack.run.stages[1].rays_in, with_repack.run.stages[2].rays_in);  // trace saw every ray once
}

TEST(Repack, RefusesAChainWithZsortToo) {
  Config config;
  config.set("reorder.heuristic=origin");
  config.set(R"(pipeline.stages=["generate", "zsort", "repack", "trace", "shade", "spawn"])");
  try {
    plan_render(config);
    FAIL() << "accepted";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("'repack' and 'zsort'"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace wavetrace
