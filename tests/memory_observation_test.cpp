// Probed traversal: the same answers as unprobed, reads that all fall inside the world's
// spans, repeatable single-thread counts, and the counters in the render's stats.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/pipeline/memory_observation.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/pipeline/tracing_arena.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

const Scene& sphere() {
  static const Scene scene = make_builtin_scene("builtin:sphere:50k");
  return scene;
}

MemoryPlan plan_with(const std::vector<std::string>& settings) {
  Config config;
  for (const std::string& setting : settings) config.set(setting);
  return plan_memory(config);
}

struct ProbedPass {
  PagerCounters pager;
  CacheCounters cache;
  std::uint64_t outside = 0;
  std::vector<std::unique_ptr<HitBatch>> hits;
};

ProbedPass probed_pass(const Accelerator& accelerator, const RaySet& rays, const std::string& budget) {
  const MemoryPlan plan = plan_with({"memory.budget=" + budget, "memory.page_bytes=16384", "memory.cache=l2"});
  SimulatedPager pager(accelerator.memory_spans(), plan.page_bytes, *plan.budget, plan.io);
  CacheBank caches(*plan.cache, 1);
  ProbedPass pass;
  TracingArena arena(1);
  arena.execute([&] { pass.hits = trace_ray_set_probed(accelerator, rays, MemoryObservers{&pager, &caches}); });
  pass.pager = pager.counters(0);
  pass.cache = caches.total(0);
  pass.outside = pager.outside_accesses();
  return pass;
}

class ProbedBvh : public ::testing::TestWithParam<std::string> {};

TEST_P(ProbedBvh, AnswersAsUnprobedAndReadsOnlyItsWorld) {
  Config config;
  config.set("accel.type=bvh");
  for (const std::string& setting : {GetParam()}) {
    if (!setting.empty()) config.set(setting);
  }
  const auto accelerator = make_accelerator(sphere().mesh, accelerator_options(config));
  ASSERT_TRUE(accelerator->probed());
  const auto embree = make_accelerator(sphere().mesh, AcceleratorOptions{});
  for (RaySetKind kind : {RaySetKind::primary, RaySetKind::shadow}) {
    const RaySet rays = make_ray_set(kind, sphere(), *embree, 20000);
    const auto plain = trace_ray_set(*accelerator, rays);
    const ProbedPass pass = probed_pass(*accelerator, rays, "100%");
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(pass.hits[b]->primitive[i], plain[b]->primitive[i]);
        ASSERT_EQ(pass.hits[b]->t[i], plain[b]->t[i]);
      }
    }
    EXPECT_EQ(pass.outside, 0u);
    EXPECT_GT(pass.pager.accesses, 20000u * 3);  // root, children, triangles, vertices
    EXPECT_GT(pass.cache.accesses, 20000u * 3);
    EXPECT_GT(pass.pager.faults, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, ProbedBvh,
                         ::testing::Values("", "accel.bvh.width=8", "accel.bvh.triangle_order=morton",
                                           "accel.bvh.triangle_order=leaf", "accel.bvh.layout=veb", "accel.type=grid",
                                           "accel.type=mlgrid", "accel.type=arraygrid"));

TEST(MemoryObservation, SingleThreadCountsRepeatAndBudgetsOrderFaults) {
  const auto accelerator = make_accelerator(sphere().mesh, [] {
    AcceleratorOptions options;
    options.type = "bvh";
    return options;
  }());
  const auto embree = make_accelerator(sphere().mesh, AcceleratorOptions{});
  const RaySet rays = make_ray_set(RaySetKind::diffuse, sphere(), *embree, 20000);
  const ProbedPass full = probed_pass(*accelerator, rays, "100%");
  const ProbedPass again = probed_pass(*accelerator, rays, "100%");
  EXPECT_EQ(full.pager.faults, again.pager.faults);
  EXPECT_EQ(full.pager.accesses, again.pager.accesses);
  EXPECT_EQ(full.cache.misses, again.cache.misses);
  std::size_t world = 0;
  for (const auto& span : accelerator->memory_spans()) world += span.size();
  EXPECT_LE(full.pager.faults, world / 16384 + accelerator->memory_spans().size());  // each page once at most
  const ProbedPass half = probed_pass(*accelerator, rays, "50%");
  const ProbedPass tenth = probed_pass(*accelerator, rays, "10%");
  EXPECT_GT(half.pager.faults, full.pager.faults);
  EXPECT_GT(tenth.pager.faults, half.pager.faults);
  EXPECT_EQ(tenth.pager.accesses, full.pager.accesses);
}

TEST(MemoryObservation, BadMemoryKeysNameTheKey) {
  EXPECT_THROW(plan_with({"memory.budget=lots"}), ConfigError);
  EXPECT_THROW(plan_with({"memory.budget=0%"}), ConfigError);
  EXPECT_THROW(plan_with({"memory.page_bytes=5000"}), ConfigError);
  EXPECT_THROW(plan_with({"memory.cache=custom"}), ConfigError);
  EXPECT_THROW(plan_with({"memory.cache=l2", "memory.cache_ways=7"}), ConfigError);
  EXPECT_THROW(plan_with({"memory.cache=l9"}), ConfigError);
  const MemoryPlan custom = plan_with({"memory.cache=custom", "memory.cache_bytes=65536", "memory.cache_ways=4"});
  ASSERT_TRUE(custom.cache.has_value());
  EXPECT_EQ(custom.cache->sets(), 256u);
  EXPECT_FALSE(plan_with({}).enabled());
  try {
    plan_with({"memory.budget=lots"});
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("memory.budget"), std::string::npos) << error.what();
  }
}

TEST(MemoryObservation, RenderStatsCarryPagerAndCacheObjectsAndEmbreeHasNone) {
  const std::string stats = testing::write_temp_file("memory_stats.json", "");
  const std::string common = " --size 24x16 --spp 1 --threads 1 --set memory.budget=20% --set memory.page_bytes=65536"
                             " --set memory.cache=paper_l2 --out " + testing::write_temp_file("memory.exr", "") +
                             " --stats " + stats;
  auto result = testing::run_wavetrace("render builtin:room:20k --accel bvh" + common);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("trace pager:"), std::string::npos) << result.output;
  nlohmann::json json = nlohmann::json::parse(std::ifstream(stats));
  bool found = false;
  for (const auto& stage : json["stages"]) {
    if (stage["name"] != "trace") {
      EXPECT_FALSE(stage.contains("pager"));
      continue;
    }
    found = true;
    for (const char* key : {"page_bytes", "budget_bytes", "accesses", "faults", "bytes_loaded", "simulated_io_seconds"}) {
      EXPECT_TRUE(stage["pager"].contains(key)) << key;
    }
    for (const char* key : {"line_bytes", "capacity_bytes", "ways", "accesses", "misses"}) {
      EXPECT_TRUE(stage["cache"].contains(key)) << key;
    }
    EXPECT_EQ(stage["pager"]["page_bytes"], 65536);
    EXPECT_GT(stage["pager"]["faults"].get<std::uint64_t>(), 0u);
    EXPECT_EQ(stage["cache"]["capacity_bytes"], 6u << 20);
  }
  EXPECT_TRUE(found);

  result = testing::run_wavetrace("render builtin:room:20k --accel embree" + common);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("cannot report its memory reads"), std::string::npos) << result.output;
  json = nlohmann::json::parse(std::ifstream(stats));
  for (const auto& stage : json["stages"]) {
    EXPECT_FALSE(stage.contains("pager"));
    EXPECT_FALSE(stage.contains("cache"));
  }
}

}  // namespace
}  // namespace wavetrace
