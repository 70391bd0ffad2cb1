// The megakernel, the wavefront's control experiment: the same image bit for bit with every
// accelerator, the same rays traced, its reads observed, and settings only the wavefront
// honours refused.
#include <gtest/gtest.h>

#include "render_support.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {
namespace {

RenderOutput render(const Scene& scene, std::vector<std::string> settings) {
  settings.insert(settings.begin(), {"render.width=40", "render.height=30", "render.spp=2"});
  return testing::render_scene(scene, settings);
}

const Scene& room() {
  static const Scene scene = make_builtin_scene("builtin:room:20k");
  return scene;
}

std::uint64_t rays_traced(const RenderOutput& output) {
  for (const StageStats& stage : output.run.stages) {
    if (stage.name == "trace" || stage.name == "megakernel") return stage.rays_in;
  }
  return 0;
}

class MegakernelImage : public ::testing::TestWithParam<std::vector<std::string>> {};

TEST_P(MegakernelImage, IsBitIdenticalToTheWavefronts) {
  std::vector<std::string> wavefront = GetParam(), megakernel = GetParam();
  wavefront.push_back("render.threads=2");
  megakernel.insert(megakernel.end(), {"pipeline.mode=megakernel", "pipeline.tile=7", "render.threads=2"});
  const RenderOutput a = render(room(), wavefront);
  const RenderOutput b = render(room(), megakernel);
  double sum = 0.0;
  for (float value : a.image) sum += value;
  EXPECT_GT(sum, 0.0);
  ASSERT_EQ(a.image.size(), b.image.size());
  EXPECT_TRUE(a.image == b.image);
  EXPECT_EQ(rays_traced(a), rays_traced(b));
  ASSERT_EQ(b.run.stages.size(), 1u);
  EXPECT_EQ(b.run.stages[0].name, "megakernel");
  EXPECT_EQ(b.run.threads, 2);
}

INSTANTIATE_TEST_SUITE_P(
    EveryAccelerator, MegakernelImage,
    ::testing::Values(std::vector<std::string>{"accel.type=embree", "accel.embree.queries=single"},
                      std::vector<std::string>{"accel.type=embree", "accel.embree.queries=stream"},
                      std::vector<std::string>{"accel.type=bvh"}, std::vector<std::string>{"accel.type=bvh", "accel.bvh.width=8"},
                      std::vector<std::string>{"accel.type=hmq"}, std::vector<std::string>{"accel.type=hmq", "accel.hmq.width=8"},
                      std::vector<std::string>{"accel.type=raystrips"},
                      std::vector<std::string>{"accel.type=raystrips", "accel.raystrips.width=8"},
                      std::vector<std::string>{"accel.type=grid"}));

TEST(Megakernel, ImageIsIdenticalForThreadsAndTiles) {
  const RenderOutput reference = render(room(), {"pipeline.mode=megakernel", "render.threads=1", "pipeline.tile=64"});
  for (const auto& variant : {std::vector<std::string>{"pipeline.mode=megakernel", "render.threads=2", "pipeline.tile=1"},
                              std::vector<std::string>{"pipeline.mode=megakernel", "render.threads=2", "pipeline.tile=13"}}) {
    EXPECT_TRUE(render(room(), variant).image == reference.image) << variant[2];
  }
}

TEST(Megakernel, MatchesTheWavefrontWithReordering) {
  const RenderOutput megakernel = render(room(), {"pipeline.mode=megakernel"});
  const RenderOutput hph = render(room(), {"reorder.heuristic=hph", "proxy.share=0.05"});
  EXPECT_TRUE(megakernel.image == hph.image);
}

// Observed ([memory]), each ray's walk reads through the trace stage's probe: the pager counts
// the megakernel's reads as a "trace" stage beside it, and the image does not change.
TEST(Megakernel, ItsWalksReadsAreCountedAsTraces) {
  const std::vector<std::string> settings = {"pipeline.mode=megakernel", "accel.type=hmq", "accel.hmq.width=8",
                                             "render.threads=2"};
  const RenderOutput plain = render(room(), settings);
  std::vector<std::string> observed = settings;
  observed.insert(observed.end(), {"memory.budget=20%", "memory.page_bytes=4096"});
  const RenderOutput paged = render(room(), observed);
  EXPECT_TRUE(paged.image == plain.image);
  ASSERT_EQ(plain.run.stages.size(), 1u);
  ASSERT_EQ(paged.run.stages.size(), 2u);
  const StageStats& walks = paged.run.stages[1];
  EXPECT_EQ(walks.name, "trace");
  EXPECT_EQ(walks.rays_in, paged.run.stages[0].rays_in);
  EXPECT_GT(walks.seconds, 0.0);
  EXPECT_LE(walks.seconds, paged.run.stages[0].seconds);
  ASSERT_TRUE(walks.pager.has_value());
  EXPECT_GT(walks.pager->counters.faults, 0u);
  EXPECT_GT(walks.pager->counters.accesses, walks.pager->counters.faults);
}

TEST(Megakernel, RefusesWhatOnlyTheWavefrontHonours) {
  const auto refusal = [](const std::vector<std::string>& settings) -> std::string {
    try {
      Config config;
      for (const std::string& setting : settings) config.set(setting);
      plan_render(config);
    } catch (const ConfigError& error) {
      return error.what();
    }
    return "accepted";
  };
  EXPECT_NE(refusal({"pipeline.mode=megakernel", "reorder.heuristic=hph"}).find("reorder.heuristic = 'hph'"),
            std::string::npos);
  EXPECT_NE(refusal({"pipeline.mode=megakernel", "pipeline.stages=[\"generate\", \"trace\", \"shade\"]"})
                .find("pipeline.stages"),
            std::string::npos);
  EXPECT_NE(refusal({"pipeline.mode=megakernel", "memory.budget=50%", "memory.look_ahead=4"}).find("memory.look_ahead"),
            std::string::npos);
  EXPECT_EQ(refusal({"pipeline.mode=megakernel", "memory.budget=50%"}), "accepted");
  EXPECT_NE(refusal({"pipeline.mode=sideways"}).find("sideways"), std::string::npos);
  EXPECT_EQ(refusal({"pipeline.mode=megakernel"}), "accepted");
}

}  // namespace
}  // namespace wavetrace
