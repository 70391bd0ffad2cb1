// Config: defaults, TOML files, --set overrides, and every kind of bad input naming its key.
#include <cstdlib>

#include <gtest/gtest.h>

#include "wavetrace/setup/config.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

void expect_config_error(const std::function<void()>& action, const std::string& fragment) {
  try {
    action();
    FAIL() << "no error; expected one mentioning " << fragment;
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
  }
}

TEST(Config, DefaultsCoverEveryKeyWithADefault) {
  const Config config;
  EXPECT_EQ(config.text("scene.source"), "builtin:default");
  EXPECT_EQ(config.integer("render.spp"), 8);
  EXPECT_EQ(config.text("accel.type"), "embree");
  EXPECT_FALSE(config.has("camera.position"));
  EXPECT_EQ(config.text_list("pipeline.stages"), std::vector<std::string>{"auto"});  // the chain reorder.heuristic needs
}

TEST(Config, LoadsTomlWithNestedTables) {
  Config config;
  config.load_string(R"(
[scene]
source = "builtin:sphere:1k"
[camera]
position = [1, 2, 3.5]
fov = 55
[render]
spp = 3
pixel_order = "zcurve"
[accel.embree]
mode = "robust"
[pipeline]
stages = ["generate", "trace"]
)");
  EXPECT_EQ(config.text("scene.source"), "builtin:sphere:1k");
  EXPECT_EQ(config.vector3("camera.position"), glm::vec3(1.0f, 2.0f, 3.5f));
  EXPECT_DOUBLE_EQ(config.real("camera.fov"), 55.0);
  EXPECT_EQ(config.integer("render.spp"), 3);
  EXPECT_EQ(config.text("accel.embree.mode"), "robust");
  EXPECT_EQ(config.text_list("pipeline.stages"), (std::vector<std::string>{"generate", "trace"}));
}

TEST(Config, SetParsesByType) {
  Config config;
  config.set("render.spp=16");
  config.set("camera.look_at=0,1,2");
  config.set("camera.up=[0, 0, 1]");
  config.set("camera.fov=30.5");
  config.set("pipeline.stages=generate,trace,shade");
  config.set("accel.embree.mode=compact");
  EXPECT_EQ(config.integer("render.spp"), 16);
  EXPECT_EQ(config.vector3("camera.look_at"), glm::vec3(0, 1, 2));
  EXPECT_EQ(config.vector3("camera.up"), glm::vec3(0, 0, 1));
  EXPECT_DOUBLE_EQ(config.real("camera.fov"), 30.5);
  EXPECT_EQ(config.text_list("pipeline.stages").size(), 3u);
  EXPECT_EQ(config.text("accel.embree.mode"), "compact");
}

TEST(Config, BadInputNamesTheKey) {
  Config config;
  expect_config_error([&] { config.set("render.sppp=4"); }, "unknown config key 'render.sppp'");
  expect_config_error([&] { config.set("rendr.spp=4"); }, "unknown config section 'rendr'");
  expect_config_error([&] { config.set("reorder.strategy=hph"); }, "reorder.strategy");
  expect_config_error([&] { config.set("reorder.heuristic=hph_magic"); }, "reorder.heuristic");
  expect_config_error([&] { config.set("render.spp=0"); }, "render.spp = 0 is out of range");
  expect_config_error([&] { config.set("render.spp=many"); }, "render.spp");
  expect_config_error([&] { config.set("render.width=64.5"); }, "render.width");
  expect_config_error([&] { config.set("camera.fov=400"); }, "camera.fov");
  expect_config_error([&] { config.set("camera.position=1,2"); }, "camera.position");
  expect_config_error([&] { config.set("camera.position=1,nan,2"); }, "camera.position");
  expect_config_error([&] { config.set("accel.type=octree"); }, "accel.type = 'octree' is not one of");
  expect_config_error([&] { config.set("pipeline.stages=generate,teleport"); }, "teleport");
  expect_config_error([&] { config.set("render.spp"); }, "section.key=value");
  expect_config_error([&] { config.load_string("[render]\nspp = \"eight\"\n"); }, "render.spp");
  expect_config_error([&] { config.load_string("[render]\nbogus = 1\n"); }, "render.bogus");
  expect_config_error([&] { config.load_string("spp = 1\n"); }, "inside a section");
  expect_config_error([&] { config.load_string("[render\nspp = 1\n"); }, "config:");
  expect_config_error([&] { config.load_file("/nonexistent/config.toml"); }, "/nonexistent/config.toml");
}

// The distributed render's keys, refused as every key is: by name, with the value and what is allowed.
TEST(Config, DistributeKeysNameTheirBadValues) {
  Config config;
  expect_config_error([&] { config.set("distribute.replicate=1.5"); }, "distribute.replicate = 1.5 is out of range [0, 1]");
  expect_config_error([&] { config.set("distribute.replicate=-0.1"); }, "distribute.replicate = -0.1 is out of range");
  expect_config_error([&] { config.set("distribute.replicate=nan"); }, "distribute.replicate = nan is out of range");
  expect_config_error([&] { config.set("distribute.replicate=most"); }, "distribute.replicate");
  expect_config_error([&] { config.set("distribute.balance=work"); },
                      "distribute.balance = 'work' is not one of: bytes, triangles, rays");
  expect_config_error([&] { config.set("distribute.mode=mesh"); }, "distribute.mode = 'mesh' is not one of: image, data");
  expect_config_error([&] { config.set("distribute.range_rays=-5"); }, "distribute.range_rays = -5 is out of range");
  config.set("distribute.replicate=0.25");
  config.set("distribute.balance=rays");
}

TEST(Config, FileErrorsNameTheFile) {
  const std::string path = testing::write_temp_file("bad.toml", "[render]\nmax_depth = -3\n");
  Config config;
  expect_config_error([&] { config.load_file(path); }, path);
  expect_config_error([&] { config.load_file(path); }, "render.max_depth");
}

TEST(Config, StageListsThatCannotRunAreRejected) {
  const auto plan_with = [](const std::string& stages) {
    Config config;
    config.set("pipeline.stages=" + stages);
    plan_render(config);
  };
  plan_with("generate,trace");
  plan_with("generate,trace,shade");
  expect_config_error([&] { plan_with("trace,generate"); }, "must start with 'generate'");
  expect_config_error([&] { plan_with("generate,shade,trace"); }, "'shade' needs 'trace'");
  expect_config_error([&] { plan_with("generate,trace,spawn"); }, "'spawn' needs 'shade'");
  expect_config_error([&] { plan_with("generate,trace,trace,shade"); }, "more than once");
  expect_config_error([&] { plan_with("generate,trace,shade,spawn,shade"); }, "more than once");
}

TEST(Config, KeysThatOverrideEachOtherAreAConflictWhenBothAreGiven) {
  const auto plan_with = [](const std::vector<std::string>& assignments) {
    Config config;
    for (const std::string& assignment : assignments) config.set(assignment);
    plan_render(config);
  };
  // Each alone is fine; together one would silently win.
  plan_with({"accel.hmq.epsilon=0.001"});
  plan_with({"accel.hmq.bits=16"});
  expect_config_error([&] { plan_with({"accel.hmq.bits=16", "accel.hmq.epsilon=0.001"}); }, "set one of them");
  expect_config_error([&] { plan_with({"accel.hmq.epsilon=0.001", "accel.hmq.bits=12"}); }, "set one of them");
  plan_with({"reorder.buffer_bytes=1048576"});
  expect_config_error([&] { plan_with({"reorder.buffer_rays=4096", "reorder.buffer_bytes=1048576"}); },
                      "both size the reorder buffer");
  plan_with({"accel.hmq.width=8"});
  expect_config_error([&] { plan_with({"accel.hmq.width=8", "accel.hmq.top_fraction=0.05"}); },
                      "applies to the binary layout");
  // Keys that do nothing without another: an error naming both.
  plan_with({"memory.look_ahead=2", "memory.look_ahead_threads=2"});
  expect_config_error([&] { plan_with({"memory.look_ahead_threads=2"}); },
                      "memory.look_ahead_threads = 2 reads ahead of trace only with memory.look_ahead, which is 0");
  // The same keys from a file count as given too.
  expect_config_error(
      [&] {
        Config config;
        config.load_string("[accel.hmq]\nbits = 16\nepsilon = 0.5\n");
        plan_render(config);
      },
      "set one of them");
}

// accel.isa is checked against the CPU as the plan is read: a set it cannot run, or a bad
// WAVETRACE_ISA behind "auto", is a ConfigError like any bad key, not a logic error later.
TEST(Config, AKernelSetNamedBadlyIsAConfigError) {
  Config config;
  plan_render(config);
  ::setenv("WAVETRACE_ISA", "avx1024", 1);
  expect_config_error([&] { plan_render(config); }, "WAVETRACE_ISA 'avx1024': expected auto, avx2 or avx512");
  ::unsetenv("WAVETRACE_ISA");
  plan_render(config);
}

TEST(Config, RestoredSettingsAreNotGiven) {
  // A world file records every setting, defaults included; restoring them must not turn
  // a default into a choice that conflicts with the user's.
  Config config;
  config.restore("accel.hmq.bits=16");
  EXPECT_FALSE(config.given("accel.hmq.bits"));
  config.set("accel.hmq.epsilon=0.01");
  EXPECT_TRUE(config.given("accel.hmq.epsilon"));
  EXPECT_NO_THROW(plan_render(config));
  EXPECT_FALSE(Config().given("accel.type")) << "a default is not given";
}

}  // namespace
}  // namespace wavetrace
