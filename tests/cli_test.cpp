// The command line end to end: render writes images and stats; bad input exits non-zero
// with a one-line error naming the problem.
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.hpp"

namespace wavetrace {
namespace {

using testing::run_wavetrace;

std::string temp_dir() {
  const auto dir = std::filesystem::temp_directory_path() / "wavetrace_cli_tests";
  std::filesystem::create_directories(dir);
  return dir.string();
}

TEST(Cli, RenderWritesExrPngAndStats) {
  const std::string dir = temp_dir();
  const auto result = run_wavetrace("render builtin:default:2000 --size 32x24 --spp 1 --threads 2 --out " + dir +
                                    "/image.exr --stats " + dir + "/stats.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(std::filesystem::file_size(dir + "/image.exr") > 0);
  EXPECT_TRUE(std::filesystem::file_size(dir + "/image.png") > 0);
  EXPECT_NE(result.output.find("trace"), std::string::npos);
  std::ifstream file(dir + "/stats.json");
  const nlohmann::json stats = nlohmann::json::parse(file);
  EXPECT_EQ(stats["scene"]["triangles"].get<std::size_t>(), 2000u + 4);
  for (const char* key : {"vertices", "bounds", "degenerate_dropped"}) EXPECT_TRUE(stats["scene"].contains(key)) << key;
  for (const char* key : {"type", "bytes", "bytes_per_triangle", "parts", "build_seconds", "build_peak_accounted_bytes"}) {
    EXPECT_TRUE(stats["accel"].contains(key)) << key;
  }
  EXPECT_EQ(stats["accel"]["type"], "embree");
  ASSERT_EQ(stats["stages"].size(), 4u);
  for (const auto& stage : stats["stages"]) {
    for (const char* key : {"name", "rays_in", "rays_out", "seconds", "mrays_per_s"}) EXPECT_TRUE(stage.contains(key));
  }
  EXPECT_EQ(stats["stages"][0]["rays_out"].get<std::size_t>(), 32u * 24);
  // 768 camera rays and their bounces and light samples, within the default budget.
  const std::size_t peak = stats["render"]["rays_in_memory"]["peak"].get<std::size_t>();
  EXPECT_GT(peak, 0u);
  EXPECT_LE(peak, stats["render"]["rays_in_memory"]["budget"].get<std::size_t>());
  EXPECT_EQ(stats["image"]["width"], 32);
  EXPECT_EQ(stats["image"]["spp"], 1);
  EXPECT_EQ(stats["image"]["path"], dir + "/image.exr");
}

TEST(Cli, RenderReportsTheCpuItsRenderTook) {
  const std::string dir = temp_dir();
  const auto result = run_wavetrace("render builtin:room:100k --size 96x72 --spp 2 --threads 2 --out " + dir +
                                    "/cpu.exr --stats " + dir + "/cpu.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("the process's CPU"), std::string::npos) << result.output;
  const nlohmann::json render = nlohmann::json::parse(std::ifstream(dir + "/cpu.json"))["render"];
  const double user = render["cpu_seconds"]["user"].get<double>(), system = render["cpu_seconds"]["system"].get<double>();
  EXPECT_GT(user + system, 0.0);  // the kernel splits the two by ticks: either alone may read 0
  EXPECT_GE(user, 0.0);
  EXPECT_GE(system, 0.0);
  // The process's threads together: never more than the cores over the render's wall time.
  EXPECT_LE(user + system, render["seconds"].get<double>() * std::thread::hardware_concurrency() + 0.05);
}

TEST(Cli, RenderReportsResidentMemoryByPhaseFromTheOs) {
  const std::string dir = temp_dir();
  const auto result = run_wavetrace("render builtin:room:200k --accel hmq --size 32x24 --spp 1 --set "
                                    "build.chunk_triangles=50000 --out " + dir + "/memory.exr --stats " + dir +
                                    "/memory.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("memory (resident, from the OS): peak"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("chunks of up to"), std::string::npos) << result.output;
  std::ifstream file(dir + "/memory.json");
  const nlohmann::json memory = nlohmann::json::parse(file)["memory"];
  const auto after_load = memory["after_load_bytes"].get<std::size_t>();
  const auto after_build = memory["after_build_bytes"].get<std::size_t>();
  const auto after_render = memory["after_render_bytes"].get<std::size_t>();
  const auto peak = memory["peak_rss_bytes"].get<std::size_t>();
  EXPECT_GT(after_load, 0u);
  EXPECT_GT(after_build, after_load) << "the accelerator is resident after the build";
  EXPECT_GE(peak, std::max({after_load, after_build, after_render}));
}

// Where a build's time goes: each accelerator names its phases; a chunked build's own phases
// are wall seconds within its build time, its chunks' ("chunk.*") add up every chunk.
TEST(Cli, BuildStatsNameEachPhaseOfTheBuild) {
  const std::string dir = temp_dir();
  const std::map<std::string, std::vector<std::string>> phases = {
      {"hmq:width=8", {"chunk.snap", "chunk.sah", "chunk.nodes", "chunk.leaves"}},
      {"hmq", {"chunk.snap", "chunk.sah", "chunk.blocks"}},
      {"bvh:width=8", {"chunk.face_set", "chunk.bounds", "chunk.sah", "chunk.collapse", "chunk.blocks"}},
      {"raystrips:width=8", {"chunk.sah", "chunk.stripify", "chunk.top", "chunk.encode"}}};
  for (const auto& [accel, chunk_phases] : phases) {
    const auto result = run_wavetrace("build builtin:room:20k --accel " + accel + " --set build.chunk_triangles=4096 --out " +
                                      dir + "/phases.wtw --stats " + dir + "/phases.json");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    EXPECT_NE(result.output.find("build phases"), std::string::npos) << result.output;
    std::ifstream file(dir + "/phases.json");
    const nlohmann::json stats = nlohmann::json::parse(file);
    const nlohmann::json& measured = stats.at("build_phases");
    double own = 0.0;
    for (const char* phase : {"plan", "extract", "chunks", "write", "release", "top"}) {
      ASSERT_TRUE(measured.contains(phase)) << accel << " " << phase << " " << measured.dump();
      own += measured[phase].get<double>();
    }
    EXPECT_LE(own, stats.at("build_seconds").get<double>()) << accel << " " << measured.dump();
    for (const std::string& phase : chunk_phases) {
      ASSERT_TRUE(measured.contains(phase)) << accel << " " << phase << " " << measured.dump();
      EXPECT_GT(measured[phase].get<double>(), 0.0) << accel << " " << phase;
    }
    for (const auto& [phase, seconds] : measured.items()) EXPECT_GE(seconds.get<double>(), 0.0) << accel << " " << phase;
  }
}

// --threads bounds the build itself, which runs outside the render's arena.
TEST(Cli, BuildRunsOnTheThreadsItIsGiven) {
  const std::string dir = temp_dir();
  const auto result = run_wavetrace("build builtin:room:20k --accel hmq:width=8 --threads 1 --out " + dir +
                                    "/one_thread.wtw --stats " + dir + "/one_thread.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream file(dir + "/one_thread.json");
  EXPECT_EQ(nlohmann::json::parse(file).at("threads").get<int>(), 1);
}

TEST(Cli, ExportedPlyRendersStreamedInChunksAsTheBuiltinDoes) {
  const std::string dir = temp_dir();
  const auto exported = run_wavetrace("export builtin:sphere:20k --out " + dir + "/sphere.ply");
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  EXPECT_NE(exported.output.find("20480 triangles"), std::string::npos) << exported.output;
  const std::string common = " --accel hmq --size 32x24 --spp 1 --set build.chunk_triangles=4096 --out " + dir;
  const auto from_file = run_wavetrace("render " + dir + "/sphere.ply" + common + "/ply.exr --stats " + dir + "/ply.json");
  ASSERT_EQ(from_file.exit_code, 0) << from_file.output;
  EXPECT_NE(from_file.output.find("5 chunks of up to"), std::string::npos) << from_file.output;
  const auto builtin = run_wavetrace("render builtin:sphere:20k" + common + "/builtin.exr --stats " + dir + "/builtin.json");
  ASSERT_EQ(builtin.exit_code, 0) << builtin.output;
  const nlohmann::json a = nlohmann::json::parse(std::ifstream(dir + "/ply.json"));
  const nlohmann::json b = nlohmann::json::parse(std::ifstream(dir + "/builtin.json"));
  EXPECT_EQ(a["scene"]["triangles"], b["scene"]["triangles"]);
  EXPECT_EQ(a["scene"]["bounds"], b["scene"]["bounds"]);
  // The same triangles in the same chunks; only vertex numbering (and so strips) may differ.
  EXPECT_NEAR(a["accel"]["bytes"].get<double>() / b["accel"]["bytes"].get<double>(), 1.0, 0.03);
  const auto bad = run_wavetrace("export builtin:sphere:2000 --out " + dir + "/sphere.obj");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("export writes .ply files"), std::string::npos) << bad.output;
}

TEST(Cli, RenderReadsConfigFileAndOverrides) {
  const std::string dir = temp_dir();
  const std::string config = testing::write_temp_file(
      "render.toml", "[scene]\nsource = \"builtin:sphere:500\"\n[render]\nwidth = 16\nheight = 8\nspp = 1\n");
  const auto result = run_wavetrace("render --config " + config + " --set render.width=20 --set accel.embree.mode=robust --out " +
                                    dir + "/config.exr --stats " + dir + "/config.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream file(dir + "/config.json");
  const nlohmann::json stats = nlohmann::json::parse(file);
  EXPECT_EQ(stats["image"]["width"], 20);
  EXPECT_EQ(stats["image"]["height"], 8);
  EXPECT_EQ(stats["accel"]["type"], "embree-robust");
  EXPECT_EQ(stats["scene"]["source"], "builtin:sphere:500");
}

struct BadInput {
  std::string arguments;
  std::string message;
};
// ctest shows each case's arguments rather than the struct's bytes.
void PrintTo(const BadInput& input, std::ostream* out) { *out << input.arguments; }

class CliBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(CliBadInput, FailsWithOneLineNamingTheProblem) {
  const auto result = run_wavetrace(GetParam().arguments + " --out " + temp_dir() + "/never.exr");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find(GetParam().message), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find('\n'), result.output.size() - 1) << "one line: " << result.output;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CliBadInput,
    ::testing::Values(BadInput{"render /nonexistent.off", "/nonexistent.off: no such mesh file"},
                      BadInput{"render builtin:teapot", "unknown builtin scene 'teapot'"},
                      BadInput{"render --accel octree", "accel.type = 'octree' is not one of"},
                      BadInput{"render --set render.nope=1", "unknown config key 'render.nope'"},
                      BadInput{"render --set render.spp=-1", "render.spp = -1 is out of range"},
                      // 0 is no sample at all, not "the default".
                      BadInput{"render --spp 0", "render.spp = 0 is out of range [1, 65536]"},
                      BadInput{"render --size 10by10", "--size '10by10'"},
                      BadInput{"render --set pipeline.stages=generate,shade", "'shade' needs 'trace'"},
                      BadInput{"render --set camera.look_at=0,2.4,5.8", "look_at equals position"},
                      BadInput{"render --config /nonexistent.toml", "/nonexistent.toml"},
                      BadInput{"render /nonexistent/scene.toml", "/nonexistent/scene.toml: no such scene file"},
                      BadInput{"render --set memory.budget=lots", "memory.budget"},
                      BadInput{"render --set memory.cache=l3", "memory.cache = 'l3' is not one of"},
                      BadInput{"render --accel bvh:isa=avx1024", "accel.isa = 'avx1024' is not one of"},
                      BadInput{"render --set reorder.heuristic=magic", "reorder.heuristic = 'magic' is not one of"},
                      BadInput{"render --set proxy.share=2", "proxy.share = 2 is out of range"},
                      BadInput{"render --set reorder.heuristic=hph --set pipeline.stages=generate,zsort,trace",
                               "needs 'approx_hit' before 'zsort'"},
                      BadInput{"render --set build.chunk_triangles=10", "build.chunk_triangles = 10 is out of range"},
                      // Refused from its size before anything is allocated: no out-of-memory kill.
                      BadInput{"render builtin:room:4G --accel embree", "GB of memory is available"},
                      BadInput{"render builtin:room:4G --accel hmq --set build.chunk_triangles=1073741824",
                               "GB of memory is available"},
                      // Subdivision's output is sized before OpenMesh allocates it.
                      BadInput{"render builtin:sphere:200k --set scene.subdivide=6", "OpenMesh's 32-bit handles"}),
    [](const ::testing::TestParamInfo<BadInput>& info) { return "case" + std::to_string(info.index); });

TEST(Cli, InfoReportsTopology) {
  const auto result = run_wavetrace("info builtin:sphere:80 --json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json info = nlohmann::json::parse(result.output);
  EXPECT_EQ(info["triangles"], 80);
  EXPECT_EQ(info["closed"], true);
  EXPECT_EQ(info["connected_components"], 1);
  EXPECT_EQ(info["degenerate_dropped"], 0);
}

TEST(Cli, InfoCountsDroppedDegenerates) {
  const std::string path =
      testing::write_temp_file("cli_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n");
  const auto result = run_wavetrace("info " + path + " --json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(nlohmann::json::parse(result.output)["degenerate_dropped"], 1);
}

}  // namespace
}  // namespace wavetrace

namespace wavetrace {
namespace {

TEST(Cli, OutOfMemoryIsReportedWithWhatWasBeingBuilt) {
  // AddressSanitizer reserves terabytes of shadow memory, which no address-space limit allows.
  if (testing::kAddressSanitizer) GTEST_SKIP() << "an address-space limit cannot hold AddressSanitizer's shadow";
  // 300 MB of address space: the scene loads, its BVH build runs out.
  const auto [exit_code, output] = testing::run_wavetrace(
      "render builtin:sphere:2M --accel bvh --size 8x8 --spp 1 --threads 1 --out " +
          testing::write_temp_file("oom.exr", ""),
      "ulimit -v 300000;");
  ASSERT_NE(exit_code, -1) << "killed, not an error: " << output;
  EXPECT_EQ(exit_code, 1) << output;
  EXPECT_NE(output.find("wavetrace: error: out of memory building 'bvh' over 1997120 triangles"), std::string::npos)
      << output;
}

TEST(Cli, BenchReorderReportsEveryHeuristicWithTheIssuesKeys) {
  const nlohmann::json json = testing::run_bench_json(
      "reorder.json", "reorder --scene builtin:room:5000 --accel bvh --size 16x12 --spp 1 --threads 1 "
      "--heuristics none,origin,hph --set memory.budget=50% --set memory.page_bytes=4096 --set memory.cache=l1d "
      "--set proxy.accel=bvh");
  ASSERT_EQ(json["results"].size(), 3u);
  for (const auto& entry : json["results"]) {
    for (const char* key : {"heuristic", "render_seconds", "trace_seconds", "trace_mrays_per_s", "approx_hit_seconds",
                            "sort_seconds", "overhead_share", "page_faults", "simulated_io_seconds", "cache_misses",
                            "cpu_user_seconds", "cpu_system_seconds", "image_identical"}) {
      EXPECT_TRUE(entry.contains(key)) << key;
    }
    // The render's CPU, every thread of it: some, and never more than the cores over its time
    // (render_image's own set-up beside the render's: a second's slack).
    const double cpu = entry["cpu_user_seconds"].get<double>() + entry["cpu_system_seconds"].get<double>();
    EXPECT_GT(cpu, 0.0);
    EXPECT_LE(cpu, (entry["render_seconds"].get<double>() + 1.0) * std::thread::hardware_concurrency());
    EXPECT_TRUE(entry["image_identical"].get<bool>()) << entry["heuristic"];
    EXPECT_GT(entry["page_faults"].get<std::uint64_t>(), 0u);
  }
  EXPECT_EQ(json["results"][0]["approx_hit_seconds"].get<double>(), 0.0);  // none has no approx_hit
  EXPECT_GT(json["results"][2]["approx_hit_seconds"].get<double>(), 0.0);

  // With the disk buffer (an in-core part of 64 rays: every generation spills) beside none,
  // which has no buffer: the same image.
  const nlohmann::json spilled = testing::run_bench_json(
      "reorder_disk.json", "reorder --scene builtin:room:5000 --accel bvh --size 16x12 --spp 1 --threads 2 "
      "--heuristics none,hph --set reorder.buffer=disk --set reorder.buffer_rays=64");
  ASSERT_EQ(spilled["results"].size(), 2u);
  EXPECT_TRUE(spilled["results"][1]["image_identical"].get<bool>());
  EXPECT_TRUE(spilled["results"][0]["spill"].is_null());  // none has no buffer
  EXPECT_GT(spilled["results"][1]["spill"]["bytes_written"].get<std::uint64_t>(), 0u) << spilled["results"][1].dump();
  EXPECT_EQ(spilled["results"][1]["spill"]["bytes_read"], spilled["results"][1]["spill"]["bytes_written"]);
  EXPECT_TRUE(spilled["results"][1]["disk_pages_per_1000_rays"].is_null());  // no world file paged
}

// Photon mapping in the reorder bench: both passes counted, every heuristic the same image
// (the photon maps are built from deposits in key order); and bench photons against the path
// tracer, whose error shrinks as photons grow.
TEST(Cli, BenchReorderAndBenchPhotonsRunPhotonMapping) {
  const nlohmann::json reordered = testing::run_bench_json(
      "reorder_photon.json", "reorder --scene " + std::string(WAVETRACE_SOURCE_DIR) + "/scenes/caustic.toml "
      "--accel bvh --size 16x12 --spp 1 --threads 2 --heuristics none,hph --set render.integrator=photon "
      "--set photon.count=20000 --set photon.gather_rays=2",
      "photon mapping (20000 photons");
  ASSERT_EQ(reordered["results"].size(), 2u);
  for (const auto& entry : reordered["results"]) {
    EXPECT_GT(entry["photon_seconds"].get<double>(), 0.0);
    EXPECT_LT(entry["photon_seconds"].get<double>(), entry["render_seconds"].get<double>());
    EXPECT_TRUE(entry["image_identical"].get<bool>());
  }
  const nlohmann::json json = testing::run_bench_json(
      "photons.json", "photons --scene " + std::string(WAVETRACE_SOURCE_DIR) + "/scenes/caustic.toml --size 20x15 "
      "--spp 2 --threads 2 --reference-spp 64 --photons 1k,100k --radii 0,0.05");
  ASSERT_EQ(json["results"].size(), 4u);
  EXPECT_GT(json["reference"]["noise_rmse"].get<double>(), 0.0);
  EXPECT_GT(json["results"][0]["radius"].get<double>(), 0.0) << "0 resolved to a share of the scene";
  EXPECT_FLOAT_EQ(json["results"][1]["radius"].get<float>(), 0.05f);
  EXPECT_GT(json["results"][2]["caustic_photons"].get<std::uint64_t>(), json["results"][0]["caustic_photons"].get<std::uint64_t>());
  EXPECT_LT(json["results"][2]["rmse"].get<double>(), json["results"][0]["rmse"].get<double>());
}

// A key given with --set wins over a bench flag left at its default, as in `render`: before,
// `bench reorder --set reorder.curve=hilbert` rendered with the --curve default, morton.
TEST(Cli, BenchSetAssignmentsAreNotOverriddenByFlagDefaults) {
  const nlohmann::json json = testing::run_bench_json(
      "reorder_set.json", "reorder --scene builtin:room:5000 --accel bvh --size 16x12 --threads 1 --heuristics none "
      "--set reorder.curve=hilbert --set render.spp=2 --set render.width=20 --set render.pixel_order=zcurve");
  EXPECT_EQ(json["curve"], "hilbert");
  EXPECT_EQ(json["image"], "20x12, 2 spp, depth 5, camera rays in Z-curve order");
}

TEST(Cli, BenchPipelineComparesTheMegakernelWithEachHeuristic) {
  const nlohmann::json json = testing::run_bench_json(
      "pipeline.json", "pipeline --scene builtin:room:5000 --accel bvh:width=8 --size 16x12 --spp 1 --threads 1,2 "
      "--repeat 2 --heuristics none,hph");
  ASSERT_EQ(json["results"].size(), 6u);  // megakernel, none, hph at 1 and at 2 threads
  for (const auto& entry : json["results"]) {
    for (const char* key : {"mode", "heuristic", "threads", "render_seconds", "median_seconds", "rays_traced", "mrays_per_s",
                            "stages", "outside_trace_share", "speed_vs_megakernel", "thread_scaling", "image_identical"}) {
      EXPECT_TRUE(entry.contains(key)) << key;
    }
    EXPECT_EQ(entry["render_seconds"].size(), 2u);
    EXPECT_TRUE(entry["image_identical"].get<bool>()) << entry["mode"] << " " << entry["heuristic"];
    EXPECT_EQ(entry["rays_traced"], json["results"][0]["rays_traced"]);  // the same paths
  }
  EXPECT_EQ(json["results"][0]["mode"], "megakernel");
  EXPECT_TRUE(json["results"][0]["outside_trace_share"].is_null());
  EXPECT_EQ(json["results"][2]["heuristic"], "hph");
  EXPECT_EQ(json["results"][2]["stages"].size(), 6u);  // generate, approx_hit, zsort, trace, shade, spawn
  EXPECT_TRUE(json["results"][1]["thread_scaling"].is_null());
  EXPECT_FALSE(json["results"][4]["thread_scaling"].is_null());
}

TEST(Cli, BenchSortTimesEachPhaseOfZSortsFlush) {
  const nlohmann::json json = testing::run_bench_json(
      "sort.json", "sort --heuristics none,hph_origin --curves morton,hilbert --rays 5000 --batch-size 256 --repeat 2");
  EXPECT_EQ(json["rays"], 5000u);
  EXPECT_EQ(json["batch_size"], 256u);
  ASSERT_EQ(json["results"].size(), 4u);  // each heuristic on each curve, curves outermost
  EXPECT_EQ(json["results"][0]["heuristic"], "none");
  EXPECT_EQ(json["results"][3]["heuristic"], "hph_origin");
  EXPECT_EQ(json["results"][3]["curve"], "hilbert");
  for (const auto& entry : json["results"]) {
    const double flush = entry["flush_ns_per_ray"].get<double>();
    EXPECT_GT(flush, 0.0);
    EXPECT_GE(entry["gather_ns_per_ray"].get<double>(), 0.0);
    EXPECT_LE(entry["sort_ns_per_ray"].get<double>(), flush);
  }
  EXPECT_EQ(json["results"][0]["keys_ns_per_ray"], 0.0);  // none makes no keys
  EXPECT_GT(json["results"][1]["keys_ns_per_ray"].get<double>(), 0.0);
}

TEST(Cli, BenchSortRefusesWhatItCannotMeasure) {
  for (const char* arguments : {"--heuristics sideways", "--curves peano", "--rays 0", "--rays 99999999999", "--batch-size 8", "--repeat 0",
                                "--threads 0"}) {
    const auto result = testing::run_wavetrace(std::string("bench sort ") + arguments);
    EXPECT_NE(result.exit_code, 0) << arguments;
    EXPECT_EQ(result.output.find("terminate"), std::string::npos) << result.output;
  }
}

TEST(Cli, BenchPipelineRefusesWhatItCannotMeasure) {
  for (const char* arguments : {"--threads 1,x", "--heuristics sideways", "--repeat 0", "--set memory.budget=50%"}) {
    const auto result =
        testing::run_wavetrace(std::string("bench pipeline --scene builtin:room:5000 --size 8x6 ") + arguments);
    EXPECT_NE(result.exit_code, 0) << arguments;
    EXPECT_EQ(result.output.find("terminate"), std::string::npos) << result.output;
  }
}

}  // namespace
}  // namespace wavetrace
