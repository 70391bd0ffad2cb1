// The key table: every key of the schema has exactly one row that reads it into the plan,
// and a row changes what it says it changes.
#include <algorithm>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "wavetrace/setup/accelerator_spec.hpp"
#include "wavetrace/setup/config_reference.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {
namespace {

TEST(PlanKeys, EveryKeyIsOneRowWithAReader) {
  std::multiset<std::string> names;
  for (const ConfigKey& key : config_schema()) {
    names.insert(key.name);
    EXPECT_NE(key.read, nullptr) << key.name << " sets no plan field";
  }
  for (const std::string& name : names) EXPECT_EQ(names.count(name), 1u) << name << " has two rows";
}

TEST(PlanKeys, RowsSetTheFieldsTheyName) {
  Config config;
  config.set("render.width=123");
  config.set("accel.hmq.leaf_size=7");
  config.set("accel.bvh.bins=12");
  config.set("camera.fov=33");
  config.set("reorder.buffer_bytes=1048576");
  config.set("memory.cache=custom");
  config.set("memory.cache_bytes=65536");
  config.set("memory.cache_ways=4");
  config.set("render.threads=3");
  config.set("proxy.accel=bvh");
  config.set("accel.hmq.width=2");
  const RenderPlan plan = plan_render(config);
  EXPECT_EQ(plan.image.width, 123u);
  EXPECT_EQ(plan.accelerator.hmq.leaf_size, 7u);
  // One key, every SAH build's bins.
  EXPECT_EQ(plan.accelerator.bvh.bins, 12u);
  EXPECT_EQ(plan.accelerator.raystrips.bins, 12u);
  EXPECT_EQ(plan.accelerator.hmq.bins, 12u);
  EXPECT_EQ(plan.camera.vertical_fov_degrees, 33.0f);
  EXPECT_FALSE(plan.camera.position);
  EXPECT_EQ(plan.reorder.buffer_rays, std::size_t{1048576} / ZSortStage::kBytesPerBufferedRay);
  ASSERT_TRUE(plan.memory.cache);
  EXPECT_EQ(plan.memory.cache->capacity_bytes, 65536u);
  EXPECT_EQ(plan.memory.cache->ways, 4u);
  EXPECT_EQ(plan.pipeline.threads, 3);
  EXPECT_EQ(plan.accelerator.embree.threads, 3);
  // The proxy's accelerator: its own type, the main one's other options.
  EXPECT_EQ(plan.proxy.accelerator.type, "bvh");
  EXPECT_EQ(plan.proxy.accelerator.hmq.leaf_size, 7u);
  EXPECT_EQ(accelerator_options(config).hmq.width, 2u);
}

// proxy.share = auto: the paper's 2% where a pager holds the world, a tenth of it in core; a
// number is taken as it is either way.
TEST(PlanKeys, TheProxyShareFollowsWhereTheWorldIsHeld) {
  Config in_core;
  EXPECT_EQ(plan_render(in_core).proxy.share, ProxyOptions::kInCoreShare);
  EXPECT_TRUE(plan_render(in_core).proxy.share_by_holding);
  Config paged;
  paged.set("memory.budget=24%");
  EXPECT_EQ(plan_render(paged).proxy.share, ProxyOptions::kPagedShare);
  EXPECT_LT(ProxyOptions::kInCoreShare, ProxyOptions::kPagedShare);
  for (Config* config : {&in_core, &paged}) {
    config->set("proxy.share=0.05");
    EXPECT_EQ(plan_render(*config).proxy.share, 0.05);
    EXPECT_FALSE(plan_render(*config).proxy.share_by_holding);
  }
}

// The option structs' own defaults (what a C++ user gets from RenderPlan{}) are the table's:
// reading any key at its default changes nothing in a default plan.
TEST(PlanKeys, OptionStructDefaultsEqualTheTable) {
  const Config defaults;
  const RenderPlan untouched;
  for (const ConfigKey& key : config_schema()) {
    RenderPlan plan;
    key.read(defaults, key.name, plan);
    EXPECT_TRUE(plan == untouched) << key.name << "'s default in the table differs from its option struct's";
  }
}

// docs/configuration.md is the table printed; regenerate it with `build/wavetrace keys`.
TEST(PlanKeys, DocsConfigurationIsGeneratedFromTheTable) {
  std::ifstream file(std::string(WAVETRACE_SOURCE_DIR) + "/docs/configuration.md");
  ASSERT_TRUE(file) << "docs/configuration.md is missing";
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_TRUE(text.str() == configuration_markdown())
      << "docs/configuration.md is stale: run build/wavetrace keys > docs/configuration.md";
  for (const ConfigKey& key : config_schema()) {
    EXPECT_NE(text.str().find("| `" + key.name + "` |"), std::string::npos) << key.name;
  }
}

// --accel's specs, as render, build and bench take them: keys into their sections, and a
// malformed option or an unknown key named.
TEST(PlanKeys, AcceleratorSpecsSetTheirKeysAndNameWhatIsWrong) {
  Config config;
  apply_accelerator_spec(config, "hmq:width=8:chunk_triangles=125000:epsilon=pixel");
  const RenderPlan plan = plan_render(config);
  EXPECT_EQ(plan.accelerator.type, "hmq");
  EXPECT_EQ(plan.accelerator.hmq.width, 8u);
  EXPECT_EQ(plan.accelerator.chunk_triangles, 125000u);
  EXPECT_TRUE(plan.accel_goal.hmq_epsilon_pixel);
  // isa= is our walks' kernel set for our types, Embree's own key for Embree.
  Config ours, embree;
  apply_accelerator_spec(ours, "bvh:width=8:isa=avx2");
  EXPECT_EQ(ours.text("accel.isa"), "avx2");
  apply_accelerator_spec(embree, "embree:isa=avx2");
  EXPECT_EQ(embree.text("accel.embree.isa"), "avx2");
  EXPECT_EQ(embree.text("accel.isa"), "auto");
  Config automatic;
  apply_accelerator_spec(automatic, "auto:memory_budget=1GB:max_error=0");
  EXPECT_TRUE(accel_goal(automatic).automatic);
  EXPECT_EQ(accel_goal(automatic).max_error, 0.0);
  const auto message = [](const std::string& spec) {
    Config fresh;
    try {
      apply_accelerator_spec(fresh, spec);
    } catch (const ConfigError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("hmq:width").find("'width' is not key=value"), std::string::npos) << message("hmq:width");
  EXPECT_NE(message("hmq:depth=3").find("accel.hmq.depth"), std::string::npos) << message("hmq:depth=3");
  EXPECT_NE(message("octree").find("accel.type"), std::string::npos) << message("octree");
}

}  // namespace
}  // namespace wavetrace
