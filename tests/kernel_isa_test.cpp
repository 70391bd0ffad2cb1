// The kernel sets compiled into one binary (kernels/kernel_isa.hpp): the AVX-512 walks answer
// what the baseline's do, bit for bit, and a set is chosen, forced and refused by name.
#include <bit>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "accel_options.hpp"
#include "test_support.hpp"
#include "wavetrace/accel/hmq/leaf_hit.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/kernels/lane_sort.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"
#include "wavetrace/scene/load_scene.hpp"

namespace wavetrace {
namespace {

bool cpu_runs_avx512() { return runnable_kernel_isas().back() == KernelIsa::avx512; }

TEST(KernelIsa, SetsAreChosenByNameAndABadNameIsRefused) {
  EXPECT_EQ(runnable_kernel_isas().front(), KernelIsa::baseline);
  EXPECT_EQ(parse_kernel_isa(to_string(KernelIsa::baseline)), KernelIsa::baseline);
  try {
    parse_kernel_isa("avx1024");
    FAIL() << "no such set";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("accel.isa 'avx1024': expected auto, avx2 or avx512"), std::string::npos)
        << error.what();
  }
  if (!WAVETRACE_AVX512_DISPATCH) GTEST_SKIP() << "this build (-march=" WAVETRACE_ARCH ") has one set of walks";
  if (cpu_runs_avx512()) {
    EXPECT_EQ(parse_kernel_isa("avx512"), KernelIsa::avx512);
  } else {
    EXPECT_THROW(parse_kernel_isa("avx512"), std::invalid_argument);
  }
}

// The lane sort's AVX-512 path puts children in the baseline's order, ties and zeros included:
// closest hits cannot show an order (the nearest-hit rule breaks ties), so it is checked here.
TEST(KernelIsa, LaneSortOrdersChildrenAsTheBaselineDoes) {
#if WAVETRACE_AVX512_DISPATCH
  if (!cpu_runs_avx512()) GTEST_SKIP() << "this CPU has no AVX-512";
  std::mt19937 random(7);
  std::uniform_int_distribution<int> pick(0, 5);
  const float values[6] = {0.0f, 0.5f, 0.5f + 1e-7f, 1.0f, 3.0f, std::numeric_limits<float>::infinity()};
  for (int trial = 0; trial < 20000; ++trial) {
    alignas(32) float near[8];
    for (float& value : near) value = values[pick(random)];
    const unsigned entered = random() & 0xffu;
    alignas(32) std::int32_t expected[8], actual[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(expected), lane_sort::nearest_last(_mm256_load_ps(near), entered));
    _mm256_store_si256(reinterpret_cast<__m256i*>(actual), lane_sort::nearest_last_avx512(_mm256_load_ps(near), entered));
    for (int lane = 0; lane < 8; ++lane) ASSERT_EQ(expected[lane], actual[lane]) << "trial " << trial << " lane " << lane;
  }
#else
  GTEST_SKIP() << "this build (-march=" WAVETRACE_ARCH ") has one set of walks";
#endif
}

#if WAVETRACE_AVX512_DISPATCH
// Through memory: a vector of sixteen is returned in a register only between functions of
// the AVX-512 target.
[[WAVETRACE_AVX512_TARGET]] void read_sixteen_into(const std::byte* data, std::uint32_t first_bit, std::uint32_t bits,
                                                   std::uint32_t first, std::uint32_t count, std::uint32_t* out) {
  const hmq::SixteenU32 lanes = hmq::read_stream_sixteen(data, first_bit, bits, first, count);
  std::memcpy(out, &lanes, sizeof(lanes));
}
#endif

// The AVX-512 walks read a leaf's streams sixteen values at a time by permutes of one masked
// load: value for value what the scalar reader reads, at every width they take, from starting
// bits within and past the first byte, at counts that end inside, at and past a block of
// sixteen, with the stream ending at the buffer's last byte (so that a read past it faults
// under the sanitizers).
TEST(KernelIsa, SixteenLanesReadWhatTheScalarReaderReads) {
#if WAVETRACE_AVX512_DISPATCH
  if (!cpu_runs_avx512()) GTEST_SKIP() << "this CPU has no AVX-512";
  std::mt19937 random(13);
  for (const std::uint32_t lead : {0u, 3u, 7u, 45u}) {
    for (std::uint32_t bits = 1; bits <= hmq::kLaneStreamBits; ++bits) {
      for (const std::uint32_t count : {1u, 7u, 15u, 16u, 17u, 42u, 63u}) {
        std::vector<std::uint32_t> values(count);
        for (auto& v : values) v = static_cast<std::uint32_t>(random() & ((std::uint64_t{1} << bits) - 1));
        LargeArray<std::byte> out;
        hmq::BitWriter writer(out);
        for (std::uint32_t b = 0; b < lead; ++b) writer.append(1, 1);  // ones before the stream
        writer.append_stream(values, bits);
        writer.finish();
        const std::vector<std::byte> exact(out.begin(), out.end());
        for (std::uint32_t first = 0; first < count; first += 16) {
          std::uint32_t lanes[16];
          read_sixteen_into(exact.data(), lead, bits, first, count, lanes);
          for (std::uint32_t lane = 0; lane < 16; ++lane) {
            const std::uint32_t expected = first + lane < count ? values[first + lane] : 0u;
            ASSERT_EQ(lanes[lane], expected) << bits << " bits, value " << first + lane << " of " << count << " from bit " << lead;
          }
        }
      }
    }
  }
#else
  GTEST_SKIP() << "this build (-march=" WAVETRACE_ARCH ") has one set of walks";
#endif
}

// The AVX-512 walks gather a leaf's corners sixteen lanes at once, by a permute of one register
// (up to 16 vertices or slots), of two (up to 32) or a gather: each lane k < triangles holds
// triangle k's corners, for every strip layout, plain and indexed, at each vertex count.
TEST(KernelIsa, SixteenLanesGatherEveryTrianglesCorners) {
#if WAVETRACE_AVX512_DISPATCH
  if (!cpu_runs_avx512()) GTEST_SKIP() << "this CPU has no AVX-512";
  std::mt19937 random(11);
  const hmq::StripTable& table = hmq::StripTable::instance();
  std::size_t checked = 0;
  for (std::uint32_t entry = 0; entry < table.size(); ++entry) {
    const hmq::StripLayoutEntry& layout = table.entry(entry);
    for (const bool indexed : {false, true}) {
      for (const std::uint32_t vertices : {3u, 8u, 16u, 17u, 32u, 33u, 63u}) {
        if (!indexed && vertices != layout.slots) continue;  // plain strips: slot i is vertex i
        if (indexed && vertices > layout.slots) continue;
        hmq::DecodedLeaf decoded{};
        decoded.header.indexed = indexed;
        decoded.header.vertex_count = vertices;
        decoded.layout = &layout;
        for (int axis = 0; axis < 3; ++axis) {
          for (std::uint32_t v = 0; v < 64; ++v) decoded.position[axis][v] = float(axis * 1000 + v);
        }
        for (std::uint32_t slot = 0; slot < 64; ++slot) decoded.slot_vertex[slot] = random() % vertices;
        TriangleLanes<16> lanes{};
        hmq::gather_corners_sixteen(decoded, lanes);
        for (std::uint32_t k = 0; k < layout.triangles; ++k) {
          for (std::uint32_t c = 0; c < 3; ++c) {
            const glm::vec3 corner = decoded.slot_position(layout.first_slot[k] + c);
            for (int axis = 0; axis < 3; ++axis) {
              ASSERT_EQ(lanes.corner[c][axis][k], corner[axis])
                  << "entry " << entry << (indexed ? " indexed" : "") << " vertices " << vertices << " triangle " << k;
            }
          }
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, table.size());
#else
  GTEST_SKIP() << "this build (-march=" WAVETRACE_ARCH ") has one set of walks";
#endif
}

// Every accelerator whose walk is ours, through each query, on camera, diffuse and shadow
// rays: t, primitive and barycentrics bit for bit between the sets.
class KernelIsaWalks : public ::testing::TestWithParam<std::string> {};

TEST_P(KernelIsaWalks, Avx512AnswersWhatTheBaselineAnswersBitForBit) {
  if (!WAVETRACE_AVX512_DISPATCH || !cpu_runs_avx512()) GTEST_SKIP() << "this CPU or build runs no AVX-512 walks";
  const Scene scene = load_scene({"builtin:room:60k", 0});
  const auto accelerator = make_accelerator(scene.mesh, testing::options_for(GetParam()));
  const auto reference = make_accelerator(scene.mesh, testing::options_for("embree"));
  for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::diffuse, RaySetKind::shadow}) {
    const RaySet rays = make_ray_set(kind, scene, *reference, 20000);
    for (const bool coherent : {false, true}) {
      if (coherent && kind != RaySetKind::primary) continue;
      accelerator->use_isa(KernelIsa::baseline);
      ASSERT_EQ(accelerator->isa(), to_string(KernelIsa::baseline));
      const auto baseline = trace_ray_set(*accelerator, rays, coherent);
      accelerator->use_isa(KernelIsa::avx512);
      ASSERT_EQ(accelerator->isa(), "avx512");
      const auto avx512 = trace_ray_set(*accelerator, rays, coherent);
      std::size_t hits = 0;
      for (std::size_t b = 0; b < rays.batches.size(); ++b) {
        const HitBatch &e = *baseline[b], &a = *avx512[b];
        for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
          hits += e.is_hit(i);
          ASSERT_EQ(e.primitive[i], a.primitive[i]) << to_string(kind) << " ray " << i << " of batch " << b;
          if (rays.any_hit()) continue;
          ASSERT_EQ(std::bit_cast<std::uint32_t>(e.t[i]), std::bit_cast<std::uint32_t>(a.t[i])) << to_string(kind);
          ASSERT_EQ(std::bit_cast<std::uint32_t>(e.u[i]), std::bit_cast<std::uint32_t>(a.u[i])) << to_string(kind);
          ASSERT_EQ(std::bit_cast<std::uint32_t>(e.v[i]), std::bit_cast<std::uint32_t>(a.v[i])) << to_string(kind);
        }
      }
      EXPECT_GT(hits, rays.batches.size()) << to_string(kind) << ": the rays must meet the room";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Ours, KernelIsaWalks,
                         ::testing::Values("bvh", "bvh accel.bvh.width=8", "hmq", "hmq accel.hmq.width=8", "raystrips",
                                           "raystrips accel.raystrips.width=8", "grid", "arraygrid"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param.substr(0, info.param.find(' '));
                           return info.param.find("width=8") != std::string::npos ? name + "8" : name;
                         });

std::string read_bytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

// End to end: WAVETRACE_ISA=avx2 forces the lower set, the stats name the set that ran, and
// the image is the same file.
TEST(KernelIsa, ForcedBaselineRendersTheSameImage) {
  const auto dir = std::filesystem::temp_directory_path() / "wavetrace_kernel_isa_tests";
  std::filesystem::create_directories(dir);
  const std::string render = "render builtin:room:20k --accel bvh:width=8 --size 48x32 --spp 2 --threads 2";
  const std::string forced = "WAVETRACE_ISA=" + std::string(to_string(KernelIsa::baseline));
  const auto lower = testing::run_wavetrace(render + " --out " + (dir / "lower.exr").string() + " --stats " +
                                                (dir / "lower.json").string(),
                                            forced);
  ASSERT_EQ(lower.exit_code, 0) << lower.output;
  const auto best = testing::run_wavetrace(render + " --out " + (dir / "best.exr").string() + " --stats " +
                                           (dir / "best.json").string());
  ASSERT_EQ(best.exit_code, 0) << best.output;
  std::ifstream lower_stats(dir / "lower.json"), best_stats(dir / "best.json");
  EXPECT_EQ(nlohmann::json::parse(lower_stats)["accel"]["isa"], to_string(KernelIsa::baseline));
  EXPECT_EQ(nlohmann::json::parse(best_stats)["accel"]["isa"], to_string(runnable_kernel_isas().back()));
  EXPECT_EQ(read_bytes((dir / "lower.exr").string()), read_bytes((dir / "best.exr").string()));

  const auto bad = testing::run_wavetrace(render + " --out " + (dir / "never.exr").string(), "WAVETRACE_ISA=avx1024");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("WAVETRACE_ISA 'avx1024': expected auto, avx2 or avx512"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace wavetrace
