// What loading a world file leaves resident in this process: everything its checks touched, or,
// for a data-parallel rank, not the chunks it has checked.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/setup/world_file.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

// Kilobytes of `path`'s mapping resident in this process (its /proc/self/smaps entry).
std::size_t resident_kilobytes_of_mapping(const std::string& path) {
  std::ifstream smaps("/proc/self/smaps");
  const std::string absolute = std::filesystem::absolute(path).string();
  std::size_t total = 0;
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    if (!line.empty() && std::isxdigit(static_cast<unsigned char>(line[0])) && line.find('-') < 16) {
      inside = line.ends_with(absolute);
    } else if (inside && line.starts_with("Rss:")) {
      total += std::stoull(line.substr(4));
    }
  }
  return total;
}

// A data-parallel rank's load (CheckedPages::given_back) gives each chunk's pages back once
// it is checked: after the load it holds a small part of what a whole load holds.
TEST(WorldFile, ALoadThatGivesBackCheckedChunksHoldsLittleOfTheWorld) {
  const std::string world = testing::write_temp_file("given_back.wtw", "");
  const auto built = testing::run_wavetrace("build builtin:room:200k --accel hmq:width=8 "
                                            "--set build.chunk_triangles=16384 --out " + world);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  std::size_t kept = 0, given_back = 0;
  {
    const std::unique_ptr<LoadedWorld> loaded = load_world(world, std::nullopt, 1, CheckedPages::kept);
    kept = resident_kilobytes_of_mapping(world);
  }
  {
    const std::unique_ptr<LoadedWorld> loaded = load_world(world, std::nullopt, 1, CheckedPages::given_back);
    given_back = resident_kilobytes_of_mapping(world);
  }
  EXPECT_GT(kept, 1000u) << "the checks of a whole load touch the world (about 2 MB)";
  EXPECT_LT(given_back, kept / 4) << kept << " KB kept against " << given_back << " KB given back";
}

}  // namespace
}  // namespace wavetrace
