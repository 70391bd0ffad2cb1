// The accelerator registry: one row per type, and every fact the rest of the code asks of a
// type comes from it (config choices, making, saving and loading, auto's candidates).
#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/setup/config.hpp"

namespace wavetrace {
namespace {

TEST(AcceleratorRegistry, ConfigChoicesAreTheRowsThenAuto) {
  std::vector<std::string> expected = accelerator_names();
  expected.push_back("auto");
  const auto& schema = config_schema();
  const auto key = std::find_if(schema.begin(), schema.end(), [](const ConfigKey& k) { return k.name == "accel.type"; });
  ASSERT_NE(key, schema.end());
  EXPECT_EQ(key->choices, expected);
  EXPECT_EQ(find_accelerator_type("auto"), nullptr);
  try {
    accelerator_type("octree");
    FAIL() << "an unknown type was found";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("unknown accelerator 'octree' (available: embree, bvh"), std::string::npos)
        << error.what();
  }
}

// Every row makes its type (the tinybvh peer where this build carries it, else an error
// naming the CMake option); a row that loads gets its structure back from a file under one
// of its saved kinds, and a row that does not (rebuilt on load) is not asked to.
TEST(AcceleratorRegistry, EveryRowMakesAndTheSavingRowsLoadWhatTheySaved) {
  const Scene scene = make_builtin_scene("builtin:sphere:2000");
  for (const AcceleratorType& type : accelerator_types()) {
    AcceleratorOptions options;
    options.type = std::string(type.name);
    if (type.name == "tinybvh" && !tinybvh_built_in()) {
      try {
        make_accelerator(scene.mesh, options);
        FAIL() << "tinybvh was made in a build without it";
      } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("-DWAVETRACE_TINYBVH="), std::string::npos) << error.what();
      }
      continue;
    }
    const auto accelerator = make_accelerator(scene.mesh, options);
    ASSERT_NE(accelerator, nullptr) << type.name;
    EXPECT_EQ(saves_structure(type.name), type.load != nullptr) << type.name;
    if (type.load == nullptr) continue;
    const std::string path = testing::write_temp_file("registry_" + std::string(type.name) + ".wtw", "");
    {
      SectionWriter out(path);
      accelerator->save(out, "world/");
      out.finish();
    }
    SectionLoader in(SectionFile::open(path), "world/");
    const auto loaded = load_accelerator(in);
    EXPECT_EQ(loaded->name(), accelerator->name()) << type.name;
    EXPECT_EQ(loaded->memory().total(), accelerator->memory().total()) << type.name;
  }
}

// auto's candidates are the rows with a speed; the ones that hold their own geometry are the
// ones that can be built from a streamed scene, and only chunk-building rows build in chunks.
TEST(AcceleratorRegistry, RowsSayWhatAutoAndTheWorldBuilderAsk) {
  std::vector<std::string> candidates;
  for (const AcceleratorType& type : accelerator_types()) {
    if (type.automatic.relative_speed > 0.0) candidates.emplace_back(type.name);
    if (type.holds_own_geometry) {
      EXPECT_TRUE(type.builds_in_chunks) << type.name;
    }
    if (type.automatic.relative_speed > 0.0) {
      AcceleratorOptions options;
      options.type = std::string(type.name);
      type.automatic.set_up(options, 0.01);
      EXPECT_TRUE(type.automatic.spec(0.01).starts_with(type.name)) << type.name;
    }
  }
  EXPECT_EQ(candidates, (std::vector<std::string>{"embree", "bvh", "raystrips", "hmq", "mlgrid"}));
  EXPECT_FALSE(holds_own_geometry("auto"));
  EXPECT_FALSE(builds_in_chunks("embree"));
}

}  // namespace
}  // namespace wavetrace
