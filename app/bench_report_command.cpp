// `wavetrace bench report OUT/`: runs the report's matrix (bench/report_matrix.cpp), each
// run a wavetrace process of its own (its peak memory its own, its command line the one
// the report prints), or takes earlier bench JSON files, then has bench/report.py draw the
// charts and write OUT/report.md.
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/bench/report_matrix.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/setup/config.hpp"

namespace wavetrace {
namespace {

namespace fs = std::filesystem;

struct ReportArguments {
  std::string out;
  std::vector<std::string> from;
  bool quick = false;
  std::string python = "/usr/bin/python3";  // Debian's, which has matplotlib
  std::string script = std::string(WAVETRACE_SOURCE_DIR) + "/bench/report.py";
  std::string mesh = std::string(WAVETRACE_SOURCE_DIR) + "/data/bunny00.off";
};

std::size_t triangles_of(const std::string& source, const std::vector<std::string>& settings) {
  if (const auto count = builtin_triangle_count(source)) return *count;
  SceneRequest request{source, 0, false};
  for (std::size_t i = 0; i + 1 < settings.size(); ++i) {
    if (settings[i] == "--set" && settings[i + 1].starts_with("scene.subdivide=")) {
      request.subdivide = std::stoi(settings[i + 1].substr(16));
    }
  }
  return load_scene(request).triangle_count;
}

void write_json(const fs::path& path, const nlohmann::json& json) {
  std::ofstream file(path);
  file << json.dump(2) << "\n";
  if (!file) throw std::runtime_error(fmt::format("{}: could not write", path.string()));
}

int run_report(const ReportArguments& args) {
  const fs::path out = args.out, data = out / "data", logs = out / "logs";
  fs::create_directories(data);
  fs::create_directories(logs);
  if (!fs::exists(args.script)) throw ConfigError(fmt::format("--script {}: no such file", args.script));
  nlohmann::json runs = nlohmann::json::array();
  int failed = 0;
  const auto start = std::chrono::steady_clock::now();
  if (!args.from.empty()) {
    for (const std::string& given : args.from) {
      if (!fs::is_regular_file(given)) throw ConfigError(fmt::format("--from {}: no such file", given));
      const fs::path copy = data / fs::path(given).filename();
      if (fs::absolute(given) != fs::absolute(copy)) fs::copy_file(given, copy, fs::copy_options::overwrite_existing);
      runs.push_back({{"name", copy.stem().string()}, {"section", "given"}, {"command", "(given: " + given + ")"},
                      {"seconds", 0.0}, {"status", 0}});
    }
  } else {
    ReportMatrixOptions options;
    options.quick = args.quick;
    options.data_dir = data.string();
    options.mesh_path = args.mesh;
    const ReportScenes scenes = report_scenes(options);
    options.room_triangles = triangles_of(scenes.room, {});
    options.sphere_triangles = triangles_of(scenes.sphere, {});
    options.mesh_triangles = triangles_of(scenes.mesh.front(), scenes.mesh);
    const std::string self = fs::read_symlink("/proc/self/exe").string();
    const std::vector<ReportRun> matrix = report_matrix(options);
    for (std::size_t i = 0; i < matrix.size(); ++i) {
      const ReportRun& run = matrix[i];
      const fs::path log = logs / (run.name + ".log");
      fmt::print("[{}/{}] {} ", i + 1, matrix.size(), run.name);
      std::fflush(stdout);  // the line shows while the run goes on
      const auto run_start = std::chrono::steady_clock::now();
      const int status = std::system((shell_command(self, run.arguments) + " > '" + log.string() + "' 2>&1").c_str());
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      fmt::print("{:.1f} s{}\n", seconds, code == 0 ? "" : fmt::format(" FAILED (status {}; see {})", code, log.string()));
      std::fflush(stdout);
      failed += code != 0;
      runs.push_back({{"name", run.name}, {"section", run.section}, {"command", shell_command("wavetrace", run.arguments)},
                      {"seconds", seconds}, {"status", code}});
    }
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_json(data / "runs.json", {{"quick", args.quick}, {"total_seconds", total}, {"runs", runs}});
  // The script's own error is the message: its stderr goes to a file shown when it fails.
  const fs::path errors = data / "report_py.stderr";
  const std::string plot = fmt::format("'{}' '{}' '{}'", args.python, args.script, out.string());
  if (const int status = std::system((plot + " 2> '" + errors.string() + "'").c_str()); status != 0) {
    std::ifstream error_file(errors);
    const std::string error_text((std::istreambuf_iterator<char>(error_file)), std::istreambuf_iterator<char>());
    throw std::runtime_error(fmt::format("{} failed (status {}):\n{}", plot, WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                                         error_text.empty() ? "(it printed nothing on stderr)" : error_text));
  }
  fmt::print("wrote {} ({} runs in {:.0f} s{})\n", (out / "report.md").string(), runs.size(), total,
             failed ? fmt::format(", {} FAILED", failed) : std::string());
  return failed ? 1 : 0;
}

}  // namespace

void add_bench_report_command(CLI::App& bench, int& exit_code) {
  auto args = std::make_shared<ReportArguments>();
  CLI::App* report = bench.add_subcommand(
      "report", "run the report's benchmark matrix (or take --from JSON files) and write OUT/report.md with its charts");
  report->add_option("out", args->out, "the report's folder")->required();
  report->add_option("--from", args->from, "earlier bench JSON files to chart instead of running the matrix")
      ->expected(1, 1 << 20);
  report->add_flag("--quick", args->quick, "small scenes and counts: every chart and table, in a minute or two");
  report->add_option("--python", args->python, "the Python interpreter with matplotlib (default Debian's)");
  report->add_option("--script", args->script, "the chart and report writer (bench/report.py)");
  report->add_option("--mesh", args->mesh, "the real mesh of the matrix (subdivided twice unless --quick)");
  report->callback([args, &exit_code] { exit_code = run_report(*args); });
}

}  // namespace wavetrace
