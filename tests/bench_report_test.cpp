// `wavetrace bench report`: the quick matrix produces every chart and every table row, and
// --from charts earlier JSON files.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_support.hpp"

namespace wavetrace {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "wavetrace_tests" / name;
  fs::remove_all(dir);
  return dir;
}

std::size_t count_lines_starting(const std::string& text, const std::string& prefix) {
  std::size_t count = 0;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) count += line.starts_with(prefix);
  return count;
}

TEST(BenchReport, TheQuickMatrixProducesEveryChartAndTableRow) {
  const fs::path dir = fresh_dir("report_quick");
  const auto result = testing::run_wavetrace("bench report " + dir.string() + " --quick");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const std::string report = read_text(dir / "report.md");
  for (const std::string chart : {"pareto_room_primary", "pareto_room_diffuse", "pareto_sphere_primary",
                                  "pareto_sphere_diffuse", "pareto_mesh_primary", "pareto_mesh_diffuse", "hmq_error",
                                  "hmq_image", "faults", "stages"}) {
    EXPECT_NE(report.find("](" + chart + ".png)"), std::string::npos) << chart;
    ASSERT_TRUE(fs::exists(dir / (chart + ".png"))) << chart;
    EXPECT_GT(fs::file_size(dir / (chart + ".png")), 10000u) << chart;
  }
  // Each chart's commands, with the wavetrace they ran.
  EXPECT_EQ(count_lines_starting(report, "wavetrace bench accel"), 10u);
  // auto: three settings on each of six accel runs, each against the fastest that fits.
  EXPECT_EQ(count_lines_starting(report, "| room:20k ") + count_lines_starting(report, "| sphere:20k "), 12u);
  // The goal's tally: every auto run judged, and every one's render peak against its budget.
  EXPECT_NE(report.find(" of 18 runs; its render's measured peak fits its budget on "), std::string::npos);
  EXPECT_NE(report.find(" of 18."), std::string::npos);
  // And auto's estimate of every candidate against that setting's measured render peak.
  EXPECT_NE(report.find(" estimates lie at or above the measured peak"), std::string::npos);
  EXPECT_NE(report.find("| room | raystrips:width=8:chunked | "), std::string::npos);
  for (const std::string row :
       {"| Ray-Strips on a soup", "| Hashed grid on a stadium", "| HMQ, huge extents", "| HMQ, thin features",
        "| The proxy on fur", "| Rays through shared edges"}) {
    EXPECT_NE(report.find(row), std::string::npos) << row;
  }
  EXPECT_NE(report.find("At `epsilon = pixel`"), std::string::npos);
  // Real paging next to simulated in the faults table.
  EXPECT_NE(report.find("50% real"), std::string::npos);
  std::ifstream runs_file(dir / "data" / "runs.json");
  const nlohmann::json runs = nlohmann::json::parse(runs_file);
  for (const auto& run : runs["runs"]) EXPECT_EQ(run["status"], 0) << run["name"];

  // --from: earlier JSON files, charted without running anything.
  const fs::path again = fresh_dir("report_from");
  const auto from = testing::run_wavetrace("bench report " + again.string() + " --from " +
                                           (dir / "data" / "pareto_room_primary.json").string() + " " +
                                           (dir / "data" / "hmq_image.json").string());
  ASSERT_EQ(from.exit_code, 0) << from.output;
  const std::string charted = read_text(again / "report.md");
  EXPECT_NE(charted.find("](pareto_room_primary.png)"), std::string::npos);
  EXPECT_NE(charted.find("](hmq_image.png)"), std::string::npos);
  EXPECT_NE(charted.find("(given: "), std::string::npos);
  EXPECT_TRUE(fs::exists(again / "hmq_image.png"));
}

// A new user's path: any bench JSON, whatever its file is called, charts with --from; and when
// the chart writer fails, the command shows the writer's own error, not a guess at its cause.
TEST(BenchReport, FromTakesAnyBenchJsonAndAFailingScriptShowsItsOwnError) {
  const fs::path dir = fresh_dir("report_any_name");
  fs::create_directories(dir);
  const fs::path json = dir / "a.json";
  const auto bench = testing::run_wavetrace("bench accel --scene builtin:sphere:2000 --accel bvh,hmq --count 2000 "
                                            "--repeat 1 --json " + json.string());
  ASSERT_EQ(bench.exit_code, 0) << bench.output;
  const auto from = testing::run_wavetrace("bench report " + (dir / "out").string() + " --from " + json.string());
  ASSERT_EQ(from.exit_code, 0) << from.output;
  EXPECT_NE(read_text(dir / "out" / "report.md").find("](a.png)"), std::string::npos);

  const fs::path broken = dir / "broken_report.py";
  std::ofstream(broken) << "import sys\nsys.exit('the chart writer broke on purpose')\n";
  const auto failed = testing::run_wavetrace("bench report " + (dir / "again").string() + " --from " + json.string() +
                                             " --script " + broken.string());
  EXPECT_NE(failed.exit_code, 0);
  EXPECT_NE(failed.output.find("the chart writer broke on purpose"), std::string::npos) << failed.output;
  EXPECT_EQ(failed.output.find("python3-matplotlib"), std::string::npos) << failed.output;
}

// `bench accel ARGS --repeat 1` with its JSON in the temporary file `name`.json: the report, after
// checking the command succeeded and printed `printed`.
nlohmann::json bench_accel_json(const std::string& name, const std::string& args, const std::string& printed) {
  return testing::run_bench_json(name + ".json", "accel " + args + " --repeat 1", printed);
}

// --reads: every ray reads the 8-wide root, the walk reads blocks and never the face set (the
// hit's surface comes from the block), and every read falls in one of the world's arrays.
TEST(BenchAccel, ReadsCountNodesAndLeavesARay) {
  const nlohmann::json report = bench_accel_json(
      "bench_reads", "--scene builtin:sphere:2000 --accel embree,bvh:width=8 --count 2000 --rays primary --reads",
      "reads a ray, by array");
  const nlohmann::json& embree = report["results"][0];
  EXPECT_TRUE(embree["reads_by_array"].empty());
  const nlohmann::json& wide = report["results"][1];
  const auto reads = wide["reads_by_array"].get<std::vector<std::uint64_t>>();
  const auto bytes = wide["array_bytes"].get<std::vector<std::size_t>>();
  ASSERT_EQ(reads.size(), bytes.size() + 1);
  ASSERT_GE(reads.size(), 3u);
  EXPECT_GE(reads[0], 2000u);  // nodes: the root at least, for each ray
  EXPECT_GT(reads[1], 0u);     // triangle blocks
  for (std::size_t array = 2; array < reads.size(); ++array) EXPECT_EQ(reads[array], 0u) << array;
}

// A lossy layout's diffuse rays measured again from beyond its stated error: the self-hits of
// its own surface leave the agreement, which rises on the room; an exact layout gets no such
// pass.
TEST(BenchAccel, LossyAgreementIsMeasuredAgainBeyondTheStatedError) {
  const nlohmann::json report = bench_accel_json(
      "bench_beyond_error", "--scene builtin:room:20k --accel bvh,hmq:width=8 --count 4000 --rays diffuse",
      "x its vertex error");
  const nlohmann::json& exact = report["results"][0];
  EXPECT_TRUE(exact["beyond_error_start"].is_null());
  const nlohmann::json& lossy = report["results"][1];
  ASSERT_FALSE(lossy["beyond_error_start"].is_null());
  EXPECT_NEAR(lossy["beyond_error_start"].get<double>(), 16.0 * lossy["vertex_error_max"].get<double>(), 1e-6);
  EXPECT_GE(lossy["beyond_error_hit_agreement"].get<double>(), lossy["hit_agreement"].get<double>());
  EXPECT_GE(lossy["beyond_error_prim_agreement"].get<double>(), lossy["prim_agreement"].get<double>());
  EXPECT_GT(lossy["self_hits"].get<double>(), 0.0);  // the room's flat walls: some rays meet their own quantized wall
}

}  // namespace
}  // namespace wavetrace
