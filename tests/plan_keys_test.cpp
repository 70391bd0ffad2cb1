// The key table: every key of the schema has exactly one row that reads it into the plan,
// and a row changes what it says it changes.
#include <algorithm>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "wavetrace/stages/render_setup.hpp"

namespace wavetrace {
namespace {

TEST(PlanKeys, EverySchemaKeyHasOneRowAndEveryRowAKey) {
  std::set<std::string> schema;
  for (const ConfigKey& key : config_schema()) schema.insert(key.name);
  std::multiset<std::string> rows;
  for (const PlanKey& row : plan_keys()) rows.insert(std::string(row.key));
  for (const std::string& key : schema) EXPECT_EQ(rows.count(key), 1u) << key << " is read by no row, or by two";
  for (const std::string& row : rows) EXPECT_TRUE(schema.contains(row)) << row << " is not a config key";
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

}  // namespace
}  // namespace wavetrace
