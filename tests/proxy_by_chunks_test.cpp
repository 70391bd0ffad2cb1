// A streamed build's proxy, simplified chunk by chunk: it is saved with the world, orders rays
// without changing a pixel, and prunes stochastically exactly what the whole mesh's proxy does.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/setup/world_file.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

std::string read_bytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), {});
}

TEST(ProxyByChunks, AStreamedBuildSavesAProxyThatOrdersRaysWithoutChangingAPixel) {
  const std::string world = testing::write_temp_file("chunk_proxy.wtw", "");
  const auto built = testing::run_wavetrace("build builtin:room:200k --accel hmq:width=8 --proxy "
                                            "--set build.chunk_triangles=16384 --out " + world);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  EXPECT_NE(built.output.find("saved in place, each chunk as it was built"), std::string::npos) << built.output;
  {
    const std::unique_ptr<LoadedWorld> loaded = load_world(world);
    ASSERT_NE(loaded->proxy, nullptr);
    const double share = double(loaded->proxy->mesh().triangle_count()) / double(loaded->scene.triangle_count);
    EXPECT_GT(share, 0.01) << share;  // proxy.share 2%, each chunk's clustering within ~15%
    EXPECT_LT(share, 0.03) << share;
    EXPECT_GT(loaded->proxy->surface_tolerance(), 0.0f);
    // Measured chunk by chunk, on rays from each chunk's box: 0.72 here, where each chunk of
    // 16,384 triangles keeps about 330; 0.95 on room:8M's chunks of 2M.
    EXPECT_GT(loaded->proxy->report().quality.hit_overlap, 0.5);
    EXPECT_LE(loaded->proxy->report().quality.hit_overlap, 1.0);
  }
  std::string images[3];
  const char* heuristics[3] = {"none", "hph", "hph_origin"};
  for (int h = 0; h < 3; ++h) {
    const std::string image = testing::write_temp_file(std::string("chunk_proxy_") + heuristics[h] + ".exr", "");
    const auto rendered = testing::run_wavetrace("render " + world + " --size 48x36 --spp 2 --set reorder.heuristic=" +
                                                 heuristics[h] + " --out " + image);
    ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
    images[h] = read_bytes(image);
  }
  EXPECT_FALSE(images[0].empty());
  EXPECT_EQ(images[0], images[1]);
  EXPECT_EQ(images[0], images[2]);
}

// Stochastic pruning hashes the scene's triangle ids, so the pieces joined in chunk order are
// the proxy of the whole mesh, triangle for triangle.
TEST(ProxyByChunks, StochasticPiecesAreTheWholeMeshsProxy) {
  const std::string streamed = testing::write_temp_file("stochastic_streamed.wtw", "");
  const std::string whole = testing::write_temp_file("stochastic_whole.wtw", "");
  const std::string common = "build builtin:room:200k --accel hmq:width=8 --proxy --set proxy.method=stochastic ";
  ASSERT_EQ(testing::run_wavetrace(common + "--set build.chunk_triangles=16384 --out " + streamed).exit_code, 0);
  ASSERT_EQ(testing::run_wavetrace(common + "--set build.chunk_triangles=4194304 --out " + whole).exit_code, 0);
  const std::unique_ptr<LoadedWorld> a = load_world(streamed), b = load_world(whole);
  ASSERT_NE(a->proxy, nullptr);
  ASSERT_NE(b->proxy, nullptr);
  EXPECT_GT(a->proxy->mesh().triangle_count(), 1000u);
  EXPECT_TRUE(a->proxy->mesh().triangles == b->proxy->mesh().triangles);
  EXPECT_TRUE(a->proxy->mesh().positions == b->proxy->mesh().positions);
}

}  // namespace
}  // namespace wavetrace
