// Shared images: a render split into ranges of camera rays and its films summed is the
// single render's image bit for bit, in one process (ImageShare) and across ranks started by
// mpirun (image mode); and a rank that fails ends the job with an error naming it.
#include <chrono>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>

#include "render_support.hpp"
#include "test_support.hpp"
#include "wavetrace/distribute/mpi_session.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"

namespace wavetrace {
namespace {

const std::vector<std::string> kSettings = {"render.width=40", "render.height=30", "render.spp=3",
                                            "render.threads=2", "reorder.heuristic=hph", "render.batch_size=256"};

// Two renders of one world each take every other range of 700 camera rays; the second adds
// its film into the first's. Returns the image and how many camera rays the two generated.
std::pair<std::vector<float>, std::uint64_t> render_in_two_shares(const Scene& scene,
                                                                  const std::vector<std::string>& settings) {
  const std::uint64_t total = 40 * 30 * 3;  // kSettings: 40x30 at 3 spp
  constexpr std::uint64_t kRange = 700;
  std::vector<std::int64_t> first_sums;
  std::uint64_t generated = 0;
  std::vector<float> image;
  for (std::uint64_t part = 0; part < 2; ++part) {
    std::uint64_t next = part * kRange;
    ImageShare share;
    share.camera_rays = [&] {
      if (next >= total) return CameraRayRange{};
      const CameraRayRange range{next, std::min(kRange, total - next)};
      next += 2 * kRange;
      generated += range.count;
      return range;
    };
    share.combine_film = [&](std::vector<std::int64_t>& sums) {
      if (part == 0) {
        first_sums = sums;
      } else {
        ASSERT_EQ(sums.size(), first_sums.size());
        for (std::size_t i = 0; i < sums.size(); ++i) sums[i] += first_sums[i];
      }
    };
    image = testing::render_scene(scene, settings, share).image;
  }
  return {image, generated};
}

// The shares' films summed are the whole render's image, bit for bit.
TEST(ImageShare, RangesOfCameraRaysWithTheirFilmsSummedAreTheWholeImage) {
  const Scene scene = make_builtin_scene("builtin:room:5000");
  const RenderOutput whole = testing::render_scene(scene, kSettings);
  const auto [image, generated] = render_in_two_shares(scene, kSettings);
  EXPECT_EQ(generated, 40u * 30 * 3);
  EXPECT_EQ(image, whole.image);
  double sum = 0.0;
  for (float value : image) sum += value;
  EXPECT_GT(sum, 0.0);
}

// Photon mapping shares an image the same way: each share traces every photon (the maps are
// the same in each, built in key order) and only its own camera rays.
TEST(ImageShare, PhotonMappingSharesAnImageAsThePathTracerDoes) {
  const Scene scene = make_builtin_scene("builtin:room:5000");
  std::vector<std::string> settings = kSettings;
  settings.insert(settings.end(), {"render.integrator=photon", "photon.count=20000", "photon.gather_rays=2"});
  const RenderOutput whole = testing::render_scene(scene, settings);
  EXPECT_EQ(render_in_two_shares(scene, settings).first, whole.image);
}

TEST(ImageShare, TheMegakernelCannotShareAnImage) {
  const Scene scene = make_builtin_scene("builtin:room:5000");
  ImageShare share;
  share.camera_rays = [] { return CameraRayRange{}; };
  EXPECT_THROW(testing::render_scene(scene, {"pipeline.mode=megakernel", "render.width=8", "render.height=6"}, share),
               ConfigError);
}

// mpirun as root needs its consent in the environment (CI runs as root). In the sanitizer
// build the ranks run without leak checking: Open MPI leaves allocations of its plugins (which
// it has unloaded by exit, so that no suppression can name them) at MPI_Finalize.
std::string mpirun(int ranks) {
  return fmt::format("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 ASAN_OPTIONS=detect_leaks=0 "
                     "timeout 120 mpirun --oversubscribe -np {} ",
                     ranks);
}

bool mpi_ready() { return MpiSession::built_with_mpi() && testing::run_shell("command -v mpirun").exit_code == 0; }

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const std::string kRenderArguments =
    "render builtin:room:20000 --size 40x30 --spp 3 --set reorder.heuristic=hph --set distribute.range_rays=300 ";

TEST(Distribute, ImageModeOnTwoAndThreeRanksIsTheSingleProcessImage) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun: apt-get install libopenmpi-dev openmpi-bin";
  const std::string alone = testing::write_temp_file("distribute_alone.exr", "");
  const std::string alone_stats = testing::write_temp_file("distribute_alone.json", "");
  const auto single = testing::run_wavetrace(kRenderArguments + "--threads 2 --out " + alone + " --stats " + alone_stats);
  ASSERT_EQ(single.exit_code, 0) << single.output;
  const nlohmann::json single_stats = nlohmann::json::parse(std::ifstream(alone_stats));
  EXPECT_FALSE(single_stats.contains("distribute"));  // started alone: as always
  std::uint64_t single_traced = 0;
  for (const auto& stage : single_stats["stages"]) {
    if (stage["name"] == "trace") single_traced = stage["rays_in"];
  }

  for (int ranks : {2, 3}) {
    const std::string image = testing::write_temp_file(fmt::format("distribute_{}.exr", ranks), "");
    const std::string stats = testing::write_temp_file(fmt::format("distribute_{}.json", ranks), "");
    const auto shared = testing::run_shell(mpirun(ranks) + WAVETRACE_BINARY + " " + kRenderArguments +
                                           "--threads 1 --out " + image + " --stats " + stats + " 2>&1");
    ASSERT_EQ(shared.exit_code, 0) << shared.output;
    EXPECT_EQ(read_bytes(image), read_bytes(alone)) << ranks << " ranks";
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(stats))["distribute"];
    EXPECT_EQ(report["mode"], "image");
    ASSERT_EQ(report["per_rank"].size(), std::size_t(ranks));
    std::uint64_t ranges = 0, camera_rays = 0, traced = 0;
    for (int rank = 0; rank < ranks; ++rank) {
      const nlohmann::json& own = report["per_rank"][rank];
      EXPECT_EQ(own["rank"], rank);
      EXPECT_GT(own["peak_resident_bytes"].get<std::uint64_t>(), 0u);
      // Its process's CPU over its render: some where it traced (user and system apart are
      // the kernel's split by ticks, so a short render may show either as 0), never more than
      // its cores gave.
      const double cpu = own["cpu_seconds"]["user"].get<double>() + own["cpu_seconds"]["system"].get<double>();
      if (own["camera_rays"].get<std::uint64_t>() > 0) EXPECT_GT(cpu, 0.0);
      EXPECT_LE(cpu, (own["render_seconds"].get<double>() + 1.0) * std::thread::hardware_concurrency());
      ranges += own["ranges"].get<std::uint64_t>();
      camera_rays += own["camera_rays"].get<std::uint64_t>();
      traced += own["rays_traced"].get<std::uint64_t>();
    }
    EXPECT_EQ(ranges, (40u * 30 * 3 + 299) / 300);  // every range dealt once
    EXPECT_EQ(camera_rays, 40u * 30 * 3);
    EXPECT_EQ(traced, single_traced);
    EXPECT_EQ(report["rays_traced"], traced);
  }
}

// Data mode: each rank owns a run of the chunks (10 of about 2,048 triangles) and sends the
// rays due at the others' chunks to their owners; a small flight budget keeps rank 0 from
// generating every ray before the others ask. The single process's image bit for bit.
TEST(Distribute, DataModeOnTwoAndThreeRanksIsTheSingleProcessImage) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const std::string arguments =
      "render builtin:room:20000 --accel hmq:width=8 --set build.chunk_triangles=2048 --size 64x48 --spp 4 "
      "--set reorder.heuristic=hph --set render.rays_in_flight=2048 --set distribute.range_rays=500 ";
  const std::string alone = testing::write_temp_file("data_alone.exr", "");
  const auto single = testing::run_wavetrace(arguments + "--threads 2 --out " + alone);
  ASSERT_EQ(single.exit_code, 0) << single.output;
  // Several threads a rank: several rounds in flight, and answers found by their own thread.
  std::uint64_t world_bytes = 0;
  for (const auto& [ranks, threads] : {std::pair{2, 1}, std::pair{3, 1}, std::pair{2, 3}}) {
    const std::string image = testing::write_temp_file(fmt::format("data_{}x{}.exr", ranks, threads), "");
    const std::string stats = testing::write_temp_file(fmt::format("data_{}x{}.json", ranks, threads), "");
    const auto shared = testing::run_shell(mpirun(ranks) + WAVETRACE_BINARY + " " + arguments +
                                           fmt::format("--set distribute.mode=data --threads {} --out ", threads) +
                                           image + " --stats " + stats + " 2>&1");
    ASSERT_EQ(shared.exit_code, 0) << shared.output;
    EXPECT_EQ(read_bytes(image), read_bytes(alone)) << ranks << " ranks of " << threads << " threads";
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(stats))["distribute"];
    EXPECT_EQ(report["mode"], "data");
    ASSERT_EQ(report["per_rank"].size(), std::size_t(ranks));
    EXPECT_EQ(report["balance"], "bytes");  // the default: runs weighed by their structures' bytes
    std::uint64_t chunks = 0, triangles = 0, bytes = 0, sent = 0, answered = 0;
    for (const nlohmann::json& rank : report["per_rank"]) {
      const nlohmann::json& exchange = rank["exchange"];
      EXPECT_GT(exchange["chunks_owned"].get<std::uint64_t>(), 0u) << rank.dump();
      chunks += exchange["chunks_owned"].get<std::uint64_t>();
      triangles += exchange["triangles_owned"].get<std::uint64_t>();
      bytes += exchange["bytes_owned"].get<std::uint64_t>();
      sent += exchange["rays_sent"].get<std::uint64_t>();
      answered += exchange["rays_answered"].get<std::uint64_t>();
    }
    EXPECT_EQ(chunks, 18u);  // the room's objects and parts, each cut every 2,048 triangles
    EXPECT_EQ(triangles, 20472u);
    if (world_bytes == 0) world_bytes = bytes;
    EXPECT_GT(bytes, 0u);
    EXPECT_EQ(bytes, world_bytes);  // every chunk's structure owned once, however many ranks
    EXPECT_GT(sent, 0u);
    EXPECT_EQ(sent, answered);  // every ray sent was answered by its chunk's owner
  }
}

// A round whose rays travel is suspended and its thread traces other batches (rays that
// travel on), unless WAVETRACE_SUSPEND_ROUNDS=0 keeps it waiting on its thread: the image is
// the single process's either way, and only the first suspends rounds (none under
// AddressSanitizer, which cannot follow TBB's stack switches).
TEST(Distribute, RoundsSuspendedWhileTheirRaysTravelGiveTheSingleProcessImage) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const std::string arguments =
      "render builtin:room:20000 --accel hmq:width=8 --set build.chunk_triangles=2048 --size 64x48 --spp 4 "
      "--set render.max_depth=3 --set distribute.range_rays=500 --set distribute.mode=data ";
  const std::string alone = testing::write_temp_file("suspend_alone.exr", "");
  const auto single = testing::run_wavetrace(arguments + "--threads 2 --out " + alone);
  ASSERT_EQ(single.exit_code, 0) << single.output;
#if defined(__SANITIZE_ADDRESS__)
  constexpr bool kSuspends = false;
#else
  constexpr bool kSuspends = true;
#endif
  for (const std::string setting : {"1", "0"}) {
    const std::string image = testing::write_temp_file("suspend_" + setting + ".exr", "");
    const std::string stats = testing::write_temp_file("suspend_" + setting + ".json", "");
    const auto shared = testing::run_shell("WAVETRACE_SUSPEND_ROUNDS=" + setting + " " + mpirun(2) +
                                           "-x WAVETRACE_SUSPEND_ROUNDS " + WAVETRACE_BINARY + " " + arguments +
                                           "--threads 1 --out " + image + " --stats " + stats + " 2>&1");
    ASSERT_EQ(shared.exit_code, 0) << shared.output;
    EXPECT_EQ(read_bytes(image), read_bytes(alone)) << "WAVETRACE_SUSPEND_ROUNDS=" << setting;
    std::uint64_t suspended = 0, sent = 0;
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(stats))["distribute"];
    for (const nlohmann::json& rank : report["per_rank"]) {
      suspended += rank["exchange"]["rounds_suspended"].get<std::uint64_t>();
      sent += rank["exchange"]["queries_sent"].get<std::uint64_t>();
    }
    EXPECT_GT(sent, 0u);
    if (setting == "1" && kSuspends) {
      EXPECT_GT(suspended, 0u);
      EXPECT_LE(suspended, sent);  // a round asks one query of each owner it needs
    } else {
      EXPECT_EQ(suspended, 0u);
    }
  }
}

// distribute.replicate: the chunks a probe of the view asks most are answered by every rank
// itself. The image stays the single process's; the whole world copied, no ray travels; a
// share of it, fewer rays travel than with none.
TEST(Distribute, ReplicatedChunksAreAnsweredWhereTheRaysAre) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const std::string arguments =
      "render builtin:room:20000 --accel hmq:width=8 --set build.chunk_triangles=2048 --size 64x48 --spp 2 "
      "--set render.rays_in_flight=2048 --set distribute.range_rays=500 ";
  const std::string alone = testing::write_temp_file("replicate_alone.exr", "");
  const auto single = testing::run_wavetrace(arguments + "--threads 2 --out " + alone);
  ASSERT_EQ(single.exit_code, 0) << single.output;
  std::map<std::string, std::uint64_t> rays_sent;
  for (const std::string share : {"0", "0.3", "1"}) {
    const std::string image = testing::write_temp_file("replicate_" + share + ".exr", "");
    const std::string stats = testing::write_temp_file("replicate_" + share + ".json", "");
    const auto shared = testing::run_shell(mpirun(2) + WAVETRACE_BINARY + " " + arguments +
                                           "--set distribute.mode=data --set distribute.replicate=" + share +
                                           " --threads 1 --out " + image + " --stats " + stats + " 2>&1");
    ASSERT_EQ(shared.exit_code, 0) << shared.output;
    EXPECT_EQ(read_bytes(image), read_bytes(alone)) << "replicate " << share;
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(stats))["distribute"];
    std::uint64_t owned = 0, copied = 0;
    for (const nlohmann::json& rank : report["per_rank"]) {
      const nlohmann::json& exchange = rank["exchange"];
      rays_sent[share] += exchange["rays_sent"].get<std::uint64_t>();
      owned += exchange["triangles_owned"].get<std::uint64_t>();
      copied += exchange["triangles_copied"].get<std::uint64_t>();
    }
    EXPECT_EQ(owned, 20472u);
    if (share == "0") EXPECT_EQ(copied, 0u);
    if (share == "0.3") {
      EXPECT_GT(copied, 0u);
      EXPECT_LE(copied, 20472u * 3 / 10);  // the share is of the world's triangles
    }
    if (share == "1") EXPECT_EQ(copied, 20472u);  // every rank holds every chunk
  }
  EXPECT_GT(rays_sent["0"], 0u);
  EXPECT_LT(rays_sent["0.3"], rays_sent["0"]);
  EXPECT_EQ(rays_sent["1"], 0u);

  // Chunks dealt by the probe's rays instead of triangles: another deal, the same image.
  const std::string image = testing::write_temp_file("balance_rays.exr", "");
  const std::string stats = testing::write_temp_file("balance_rays.json", "");
  const auto shared = testing::run_shell(mpirun(2) + WAVETRACE_BINARY + " " + arguments +
                                         "--set distribute.mode=data --set distribute.balance=rays --threads 1 --out " +
                                         image + " --stats " + stats + " 2>&1");
  ASSERT_EQ(shared.exit_code, 0) << shared.output;
  EXPECT_EQ(read_bytes(image), read_bytes(alone));
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(stats))["distribute"];
  EXPECT_EQ(report["balance"], "rays");
  std::uint64_t owned = 0;
  for (const nlohmann::json& rank : report["per_rank"]) owned += rank["exchange"]["triangles_owned"].get<std::uint64_t>();
  EXPECT_EQ(owned, 20472u);
}

TEST(Distribute, DataModeNeedsAChunkedWorld) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const auto result = testing::run_shell(mpirun(2) + WAVETRACE_BINARY +
                                         " render builtin:room:5000 --accel bvh --size 8x6 --set distribute.mode=data "
                                         "--out " + testing::write_temp_file("data_unchunked.exr", "") + " 2>&1");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("distribute.mode = data needs a chunked world (bvh is not)"), std::string::npos)
      << result.output;
}

// Ranks started with different arguments (here: scenes) would sum unrelated films: refused on
// every rank before anything is rendered.
TEST(Distribute, RanksWithDifferentWorldsAreRefused) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const std::string image = testing::write_temp_file("distribute_mismatch.exr", "");
  const auto result = testing::run_shell(mpirun(1) + WAVETRACE_BINARY + " render builtin:room:20000 --size 16x12 --out " +
                                         image + " : -np 1 " + WAVETRACE_BINARY +
                                         " render builtin:room:30000 --size 16x12 --out " + image + " 2>&1");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("the ranks do not render the same world and image"), std::string::npos) << result.output;
}

// Commands other than render would run once a rank (two builds writing one file): refused.
TEST(Distribute, OnlyRenderRunsUnderMpirun) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const auto result = testing::run_shell(mpirun(2) + WAVETRACE_BINARY + " build builtin:room:5000 --out " +
                                         testing::write_temp_file("distribute_build.wtw", "") + " 2>&1");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("wavetrace build runs alone: under mpirun (2 ranks) only render is shared"),
            std::string::npos)
      << result.output;
}

// Rank 1 is given a world file that does not exist: it names itself and the cause, and the
// job ends with exit 1 at once, rank 0 not left waiting at the start of the render.
TEST(Distribute, ARankThatCannotOpenItsWorldEndsEveryRank) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const std::string image = testing::write_temp_file("distribute_fault.exr", "");
  const auto start = std::chrono::steady_clock::now();
  const auto result = testing::run_shell(mpirun(1) + WAVETRACE_BINARY + " render builtin:room:20000 --size 40x30 " +
                                         "--out " + image + " : -np 1 " + WAVETRACE_BINARY +
                                         " render /nonexistent/world.wtw --out " + image + " 2>&1");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("wavetrace: error: rank 1 of 2"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("/nonexistent/world.wtw: cannot open"), std::string::npos) << result.output;
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60));
}

// Rank 1 runs out of memory making its world (400 MB of address space): it says so, naming
// itself and what it was doing, and the job ends with exit 1.
TEST(Distribute, ARankOutOfMemoryEndsEveryRank) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  if (testing::kAddressSanitizer) GTEST_SKIP() << "an address-space limit cannot hold AddressSanitizer's shadow";
  const std::string image = testing::write_temp_file("distribute_oom.exr", "");
  const std::string render = std::string(WAVETRACE_BINARY) +
                             " render builtin:sphere:2M --accel bvh --size 8x8 --spp 1 --threads 1 --out " + image;
  const auto result =
      testing::run_shell(mpirun(1) + render + " : -np 1 bash -c 'ulimit -v 400000; exec " + render + "' 2>&1");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_NE(result.output.find("wavetrace: error: rank 1 of 2"), std::string::npos) << result.output;
  // Loading or building, by how much address space MPI took first (its shared memory grows
  // with the machine's cores).
  EXPECT_NE(result.output.find("): out of memory "), std::string::npos) << result.output;
}

// Rank 1 is killed (SIGKILL) two seconds into a render of several: mpirun ends rank 0 too,
// and says which rank died of what. Its exit status is mpirun's (128 + 9), not a hang.
TEST(Distribute, ARankKilledMidRenderEndsTheJob) {
  if (!mpi_ready()) GTEST_SKIP() << "built without MPI, or no mpirun";
  const std::string image = testing::write_temp_file("distribute_killed.exr", "");
  const std::string render = std::string(WAVETRACE_BINARY) +
                             " render builtin:room:100000 --size 320x240 --spp 256 --threads 1 --out " + image;
  const auto start = std::chrono::steady_clock::now();
  const auto result = testing::run_shell(mpirun(1) + render + " : -np 1 bash -c '(sleep 2; kill -9 $$) & exec " +
                                         render + "' 2>&1");
  const auto seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_NE(result.exit_code, 124) << "timed out: " << result.output;
  EXPECT_NE(result.output.find("rank 1"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("signal 9"), std::string::npos) << result.output;
  EXPECT_LT(seconds, 60.0) << result.output;
}

}  // namespace
}  // namespace wavetrace
