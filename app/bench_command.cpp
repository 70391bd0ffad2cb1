// `wavetrace bench accel`, `bench leak`, `bench reorder`, `bench pipeline` and `bench image`.
#include <fstream>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "app/commands.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/image_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/pipeline_bench.hpp"
#include "wavetrace/bench/reorder_bench.hpp"
#include "wavetrace/stages/render_setup.hpp"
#include "wavetrace/stages/world_file.hpp"

namespace wavetrace {
namespace {

struct BenchArguments {
  std::string scene = "builtin:room:1M";
  std::string accel = "embree,bvh";
  std::string rays = "primary";
  std::string reference = "embree";
  std::size_t count = 1 << 20;
  int threads = 0;
  int repeat = 3;
  bool packets = false;
  std::string json;
  std::string budgets;
  std::vector<std::string> assignments;
};

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  for (std::string part; std::getline(stream, part, ',');) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

struct BenchSetup {
  Config config;
  Scene loaded_scene;
  std::vector<AcceleratorSpec> accelerators;
  std::unique_ptr<LoadedWorld> world;  // --scene FILE.wtw: the saved world
  // The world's own scene object: a rebuilt Embree refers to that very mesh.
  const Scene& scene() const { return world ? world->scene : loaded_scene; }
};

BenchSetup prepare(const BenchArguments& args) {
  BenchSetup setup;
  for (const std::string& assignment : args.assignments) setup.config.set(assignment);
  setup.config.set_value("scene.source", args.scene);
  if (args.threads < 0) throw ConfigError("--threads must be 0 (all cores) or more");
  if (args.count == 0) throw ConfigError("--count must be at least 1");
  for (const std::string& spec : split_commas(args.accel)) setup.accelerators.push_back(parse_accelerator_spec(spec, setup.config));
  if (setup.accelerators.empty()) throw ConfigError("--accel names no accelerator");
  if (is_world_file(args.scene)) {
    setup.world = load_world(args.scene, std::nullopt, args.threads);
    return setup;
  }
  setup.loaded_scene = load_scene(plan_render(setup.config).scene);
  for (AcceleratorSpec& spec : setup.accelerators) resolve_accelerator_spec(spec, setup.loaded_scene, setup.config);
  return setup;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream file(path);
  file << text;
  if (!file) throw std::runtime_error(fmt::format("{}: could not write", path));
}

std::string csv_path_for(const std::string& json_path) {
  const std::size_t dot = json_path.rfind('.');
  return (dot == std::string::npos ? json_path : json_path.substr(0, dot)) + ".csv";
}

int run_accel(const BenchArguments& args) {
  BenchSetup setup = prepare(args);
  AccelBenchRequest request;
  request.accelerators = setup.accelerators;
  request.reference = parse_accelerator_spec(args.reference, setup.config);
  request.rays = parse_ray_set_kind(args.rays);
  request.count = args.count;
  request.threads = args.threads;
  request.repeats = args.repeat;
  request.packets = args.packets;
  request.memory = plan_memory(setup.config);
  request.budgets = split_commas(args.budgets);
  for (const std::string& budget : request.budgets) {
    try {
      parse_memory_budget(budget);
    } catch (const std::invalid_argument& error) {
      throw ConfigError(fmt::format("--budgets: {}", error.what()));
    }
  }
  if (args.repeat < 1) throw ConfigError("--repeat must be at least 1");
  if (setup.world) {
    request.world = setup.world->accelerator.get();
    request.world_lights = setup.world->lights.get();
    request.world_label = fmt::format("{} (world file{})", setup.world->type, setup.world->rebuilt ? ", rebuilt" : "");
    request.world_load_seconds = setup.world->seconds;
  }
  const AccelBenchReport report = run_accel_bench(setup.scene(), request);
  fmt::print("{}", to_table(report));
  if (!args.json.empty()) {
    write_text(args.json, to_json(report).dump(2) + "\n");
    write_text(csv_path_for(args.json), to_csv(report));
  }
  return 0;
}

int run_leak(const BenchArguments& args) {
  if (is_world_file(args.scene)) throw ConfigError("bench leak builds each accelerator from a scene: give a scene, not a world file");
  BenchSetup setup = prepare(args);
  const LeakReport report = run_leak_bench(setup.scene(), setup.accelerators, args.count, args.threads);
  fmt::print("{}", to_table(report));
  if (!args.json.empty()) write_text(args.json, to_json(report).dump(2) + "\n");
  return 0;
}

struct ReorderArguments {
  std::string scene = "builtin:room:1M";
  std::string accel = "bvh";
  std::string heuristics = "none,origin,origin_dir,hph,hph_origin,hph_dir";
  std::string curve = "morton";
  std::string size = "320x240";
  int spp = 4;
  int threads = 0;
  std::string json;
  std::vector<std::string> assignments;
};

// A rendering benchmark's config: `defaults`, then the --set assignments, then its own flags.
Config render_bench_config(const std::vector<std::string>& defaults, const std::vector<std::string>& assignments,
                           const std::string& scene, int spp, int threads, const std::string& size) {
  Config config;
  for (const std::string& assignment : defaults) config.set(assignment);
  for (const std::string& assignment : assignments) config.set(assignment);
  config.set_value("scene.source", scene);
  config.set("render.spp=" + std::to_string(spp));
  config.set("render.threads=" + std::to_string(threads));
  const std::size_t by = size.find('x');
  if (by == std::string::npos) throw ConfigError(fmt::format("--size '{}': expected WIDTHxHEIGHT", size));
  config.set("render.width=" + size.substr(0, by));
  config.set("render.height=" + size.substr(by + 1));
  return config;
}

int run_reorder(const ReorderArguments& args) {
  Config config =
      render_bench_config({"render.max_depth=5"}, args.assignments, args.scene, args.spp, args.threads, args.size);
  config.set("accel.type=" + args.accel);
  config.set("reorder.curve=" + args.curve);
  std::vector<ReorderHeuristic> heuristics;
  for (const std::string& name : split_commas(args.heuristics)) {
    try {
      heuristics.push_back(parse_reorder_heuristic(name));
    } catch (const std::invalid_argument& error) {
      throw ConfigError(fmt::format("--heuristics: {}", error.what()));
    }
  }
  const ReorderBenchReport report = run_reorder_bench(config, heuristics);
  fmt::print("{}", to_table(report));
  if (!args.json.empty()) write_text(args.json, to_json(report).dump(2) + "\n");
  return 0;
}

struct PipelineArguments {
  std::string scene = "builtin:room:1M";
  std::string accel = "embree";
  std::string heuristics = "none,hph";
  std::string threads = "1,2";
  std::string size = "320x240";
  int spp = 4;
  int repeat = 3;
  std::string json;
  std::vector<std::string> assignments;
};

int run_pipeline(const PipelineArguments& args) {
  Config config = render_bench_config({}, args.assignments, args.scene, args.spp, 0, args.size);
  apply_accelerator_spec(config, args.accel);
  PipelineBenchRequest request;
  for (const std::string& name : split_commas(args.heuristics)) {
    try {
      request.heuristics.push_back(parse_reorder_heuristic(name));
    } catch (const std::invalid_argument& error) {
      throw ConfigError(fmt::format("--heuristics: {}", error.what()));
    }
  }
  for (const std::string& count : split_commas(args.threads)) {
    try {
      std::size_t used = 0;
      request.threads.push_back(std::stoi(count, &used));
      if (used != count.size()) throw std::invalid_argument(count);
    } catch (const std::exception&) {
      throw ConfigError(fmt::format("--threads '{}': expected comma-separated thread counts, e.g. 1,2", args.threads));
    }
  }
  request.repeats = args.repeat;
  const PipelineBenchReport report = run_pipeline_bench(config, request);
  fmt::print("{}", to_table(report));
  if (!args.json.empty()) write_text(args.json, to_json(report).dump(2) + "\n");
  return 0;
}

struct ImageArguments {
  std::string scene = "builtin:room:1M";
  std::string accel = "embree:mode=robust,hmq:bits=8,hmq:bits=12,hmq:bits=16";
  std::string size = "320x240";
  int spp = 4;
  int threads = 0;
  bool noise = false;
  std::string json;
  std::vector<std::string> assignments;
};

int run_image(const ImageArguments& args) {
  const Config config = render_bench_config({}, args.assignments, args.scene, args.spp, args.threads, args.size);
  std::vector<AcceleratorSpec> accelerators;
  for (const std::string& text : split_commas(args.accel)) accelerators.push_back(parse_accelerator_spec(text, config));
  const ImageBenchReport report = run_image_bench(config, accelerators, args.noise);
  fmt::print("{}", to_table(report));
  if (!args.json.empty()) write_text(args.json, to_json(report).dump(2) + "\n");
  return 0;
}

// --set KEY=VALUE, repeatable: config overrides applied over each benchmark's defaults.
void add_set_option(CLI::App* command, std::vector<std::string>& assignments, const std::string& example) {
  command->add_option("--set", assignments, "config override section.key=value (e.g. " + example + ")")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void add_common_options(CLI::App* command, BenchArguments& args) {
  command->add_option("--scene", args.scene, "mesh file, scene file (.toml) or builtin:NAME[:TRIANGLES]");
  command->add_option("--accel", args.accel,
                      "comma-separated accelerators, each TYPE[:key=value]..., e.g. bvh:layout=veb,embree:mode=robust");
  command->add_option("--count", args.count, "number of rays");
  command->add_option("--threads", args.threads, "worker threads (0: all cores)");
  command->add_option("--json", args.json, "write results as JSON (and CSV beside it for bench accel)");
  add_set_option(command, args.assignments, "scene.subdivide=2");
}

}  // namespace

void add_bench_command(CLI::App& app, int& exit_code) {
  CLI::App* bench = app.add_subcommand("bench", "measure accelerators side by side with Embree");
  bench->require_subcommand(1);

  auto accel_args = std::make_shared<BenchArguments>();
  CLI::App* accel = bench->add_subcommand("accel", "build and trace the same rays with each accelerator");
  add_common_options(accel, *accel_args);
  accel->add_option("--rays", accel_args->rays, "primary, diffuse, shadow or random");
  accel->add_option("--repeat", accel_args->repeat, "timed runs per accelerator (the median is reported)");
  accel->add_flag("--packets", accel_args->packets,
                  "primary rays as 2x2 packets (intersect_coherent) where an accelerator has packet traversal");
  accel->add_option("--reference", accel_args->reference,
                    "accelerator the accuracy is measured against (default embree; embree:mode=robust is watertight)");
  accel->add_option("--budgets", accel_args->budgets,
                    "simulated page pool budgets, one probed pass each, e.g. 100%,50%,20%,10% (see [memory])");
  accel->callback([accel_args, &exit_code] { exit_code = run_accel(*accel_args); });

  auto leak_args = std::make_shared<BenchArguments>();
  leak_args->accel = "embree,embree:mode=robust,bvh";
  leak_args->count = 1000000;
  CLI::App* leak = bench->add_subcommand("leak", "count rays escaping a closed mesh from inside");
  add_common_options(leak, *leak_args);
  leak->callback([leak_args, &exit_code] { exit_code = run_leak(*leak_args); });

  auto reorder_args = std::make_shared<ReorderArguments>();
  CLI::App* reorder = bench->add_subcommand("reorder", "render the same image once per ray reordering heuristic");
  reorder->add_option("--scene", reorder_args->scene, "mesh file, scene file (.toml) or builtin:NAME[:TRIANGLES]");
  reorder->add_option("--accel", reorder_args->accel, "main accelerator (accel.type)");
  reorder->add_option("--heuristics", reorder_args->heuristics,
                      "comma-separated: none, origin, origin_dir, hph, hph_origin, hph_dir (the first is the baseline)");
  reorder->add_option("--curve", reorder_args->curve, "morton or hilbert");
  reorder->add_option("--spp", reorder_args->spp, "samples per pixel");
  reorder->add_option("--size", reorder_args->size, "image size as WIDTHxHEIGHT");
  reorder->add_option("--threads", reorder_args->threads, "worker threads (0: all cores)");
  reorder->add_option("--json", reorder_args->json, "write results as JSON");
  add_set_option(reorder, reorder_args->assignments, "memory.budget=20%");
  reorder->callback([reorder_args, &exit_code] { exit_code = run_reorder(*reorder_args); });

  auto pipeline_args = std::make_shared<PipelineArguments>();
  CLI::App* pipeline = bench->add_subcommand(
      "pipeline", "the megakernel against the wavefront with each reorder heuristic: speed, stage costs, images");
  pipeline->add_option("--scene", pipeline_args->scene, "mesh file, scene file (.toml), builtin:NAME[:TRIANGLES] or world file");
  pipeline->add_option("--accel", pipeline_args->accel, "main accelerator, TYPE[:key=value]..., e.g. hmq:width=8");
  pipeline->add_option("--heuristics", pipeline_args->heuristics,
                       "comma-separated wavefront heuristics: none, origin, origin_dir, hph, hph_origin, hph_dir");
  pipeline->add_option("--threads", pipeline_args->threads, "comma-separated thread counts, each a full set of rows");
  pipeline->add_option("--spp", pipeline_args->spp, "samples per pixel");
  pipeline->add_option("--size", pipeline_args->size, "image size as WIDTHxHEIGHT");
  pipeline->add_option("--repeat", pipeline_args->repeat, "renders per row, interleaved (the median is reported)");
  pipeline->add_option("--json", pipeline_args->json, "write results as JSON");
  add_set_option(pipeline, pipeline_args->assignments, "render.max_depth=8");
  pipeline->callback([pipeline_args, &exit_code] { exit_code = run_pipeline(*pipeline_args); });

  auto image_args = std::make_shared<ImageArguments>();
  CLI::App* image = bench->add_subcommand("image", "render the same image with each accelerator, RMSE against the first");
  image->add_option("--scene", image_args->scene, "mesh file, scene file (.toml) or builtin:NAME[:TRIANGLES]");
  image->add_option("--accel", image_args->accel,
                    "comma-separated accelerators, TYPE[:key=value]...; the first renders the reference image");
  image->add_option("--spp", image_args->spp, "samples per pixel");
  image->add_option("--size", image_args->size, "image size as WIDTHxHEIGHT");
  image->add_option("--threads", image_args->threads, "worker threads (0: all cores)");
  image->add_flag("--noise", image_args->noise,
                  "also render the first accelerator with render.seed + 1: its RMSE is the Monte Carlo noise");
  image->add_option("--json", image_args->json, "write results as JSON");
  add_set_option(image, image_args->assignments, "render.max_depth=2");
  image->callback([image_args, &exit_code] { exit_code = run_image(*image_args); });

  add_bench_report_command(*bench, exit_code);
}

}  // namespace wavetrace
