// `wavetrace bench accel`, `bench leak`, `bench reorder`, `bench pipeline`, `bench sort`,
// `bench image` and `bench photons`.
#include <functional>
#include <fstream>
#include <memory>
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "app/command_options.hpp"
#include "app/commands.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/image_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/photon_bench.hpp"
#include "wavetrace/bench/pipeline_bench.hpp"
#include "wavetrace/bench/sort_bench.hpp"
#include "wavetrace/bench/reorder_bench.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_file.hpp"

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
  bool one_at_a_time = false;
  std::string json;
  std::string budgets;
  bool reads = false;
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
    // `--set memory.backing=copy` walks the world on huge pages, as the render does.
    setup.world = load_world(args.scene, std::nullopt, args.threads, CheckedPages::kept,
                             world_holding(plan_render(setup.config)));
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
  request.one_at_a_time = args.one_at_a_time;
  request.memory = plan_memory(setup.config);
  request.budgets = split_commas(args.budgets);
  request.count_reads = args.reads;
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
  int repeat = 1;
  std::string json;
  std::vector<std::string> assignments;
};

// A rendering benchmark's config: `defaults`, its own flags (defaulted or given), what
// `flags` sets besides, then the --set assignments, last, as `render` applies them: a key
// given with --set is never overridden by a flag's default.
Config render_bench_config(const std::vector<std::string>& defaults, const std::vector<std::string>& assignments,
                           const std::string& scene, int spp, int threads, const std::string& size,
                           const std::function<void(Config&)>& flags = {}) {
  Config config;
  for (const std::string& assignment : defaults) config.set(assignment);
  config.set_value("scene.source", scene);
  config.set("render.spp=" + std::to_string(spp));
  config.set("render.threads=" + std::to_string(threads));
  set_image_size(config, size);
  if (flags) flags(config);
  for (const std::string& assignment : assignments) config.set(assignment);
  return config;
}

// `--heuristics a,b,...` as what `parse` makes of each name, in order; `also` is appended to
// the error that names an unknown one.
template <typename Parse>
auto parse_heuristic_names(const std::string& list, Parse&& parse, std::string_view also = "") {
  std::vector<decltype(parse(std::string()))> parsed;
  for (const std::string& name : split_commas(list)) {
    try {
      parsed.push_back(parse(name));
    } catch (const std::invalid_argument& error) {
      throw ConfigError(fmt::format("--heuristics: {}{}", error.what(), also));
    }
  }
  return parsed;
}

std::vector<ReorderHeuristic> parse_heuristic_list(const std::string& list) {
  return parse_heuristic_names(list, parse_reorder_heuristic);
}

std::vector<ReorderBenchRow> parse_reorder_rows(const std::string& list) {
  return parse_heuristic_names(list, parse_reorder_bench_row, " (or paths: one path at a time, no reordering)");
}

int run_reorder(const ReorderArguments& args) {
  const Config config = render_bench_config({"render.max_depth=5"}, args.assignments, args.scene, args.spp, args.threads,
                                            args.size, [&](Config& flags) {
                                              apply_accelerator_spec(flags, args.accel);
                                              flags.set("reorder.curve=" + args.curve);
                                            });
  const ReorderBenchReport report = run_reorder_bench(config, parse_reorder_rows(args.heuristics), args.repeat);
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
  const Config config = render_bench_config({}, args.assignments, args.scene, args.spp, 0, args.size,
                                            [&](Config& flags) { apply_accelerator_spec(flags, args.accel); });
  PipelineBenchRequest request;
  request.heuristics = parse_heuristic_list(args.heuristics);
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

struct SortArguments {
  std::string heuristics = "hph,hph_origin";
  std::string curves = "morton,hilbert";
  std::size_t rays = 262144;
  std::size_t batch_size = 1024;
  int threads = 1;
  int repeat = 5;
  std::string json;
};

int run_sort(const SortArguments& args) {
  SortBenchRequest request;
  request.heuristics = parse_heuristic_list(args.heuristics);
  for (const std::string& name : split_commas(args.curves)) {
    try {
      request.curves.push_back(parse_curve_kind(name));
    } catch (const std::invalid_argument& error) {
      throw ConfigError(fmt::format("--curves: {}", error.what()));
    }
  }
  request.rays = args.rays;
  request.batch_size = args.batch_size;
  request.threads = args.threads;
  request.repeats = args.repeat;
  const SortBenchReport report = run_sort_bench(request);
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

struct PhotonArguments {
  std::string scene = "scenes/caustic.toml";
  std::string accel = "embree";
  std::string size = "160x120";
  int spp = 16;
  int threads = 0;
  std::uint32_t reference_spp = 4096;
  std::string photons = "10k,100k,1M";
  std::string radii;
  std::string json;
  std::vector<std::string> assignments;
};

int run_photons(const PhotonArguments& args) {
  const Config config = render_bench_config({"render.max_depth=8"}, args.assignments, args.scene, args.spp,
                                            args.threads, args.size, [&](Config& flags) {
                                              flags.set_value("accel.type", args.accel);
                                            });
  PhotonBenchRequest request;
  request.reference_spp = args.reference_spp;
  request.photon_counts.clear();
  for (const std::string& count : split_commas(args.photons)) {
    // "250k", "4M" or a plain number, as triangle counts are written.
    const std::size_t suffix = count.find_first_of("kKmM");
    const double scale = suffix == std::string::npos ? 1.0 : (count[suffix] == 'k' || count[suffix] == 'K') ? 1e3 : 1e6;
    double value = 0.0;
    try {
      std::size_t used = 0;
      value = std::stod(count.substr(0, suffix), &used) * scale;
      if (used != std::min(suffix, count.size()) || (suffix != std::string::npos && suffix + 1 != count.size())) {
        throw std::invalid_argument(count);
      }
    } catch (const std::exception&) {
      value = 0.0;
    }
    if (!(value >= 1.0 && value <= 4294967295.0)) {
      throw ConfigError(fmt::format("--photons '{}': expected comma-separated counts in [1, 2^32), e.g. 100k,1M", count));
    }
    request.photon_counts.push_back(static_cast<std::uint64_t>(value));
  }
  for (const std::string& radius : split_commas(args.radii)) {
    try {
      std::size_t used = 0;
      request.radii.push_back(std::stod(radius, &used));
      if (used != radius.size() || !(request.radii.back() >= 0.0)) throw std::invalid_argument(radius);
    } catch (const std::exception&) {
      throw ConfigError(fmt::format("--radii '{}': expected comma-separated reaches of 0 or more", args.radii));
    }
  }
  const PhotonBenchReport report = run_photon_bench(config, request);
  fmt::print("{}", to_table(report));
  if (!args.json.empty()) write_text(args.json, to_json(report).dump(2) + "\n");
  return 0;
}

void add_common_options(CLI::App* command, BenchArguments& args) {
  add_scene_option(*command, args.scene, SceneKinds::with_worlds, false);
  add_accel_option(*command, args.accel, true);
  command->add_option("--count", args.count, "number of rays");
  add_threads_option(*command, args.threads);
  command->add_option("--json", args.json, "write results as JSON (and CSV beside it for bench accel)");
  add_set_option(*command, args.assignments, "scene.subdivide=2");
}

}  // namespace

void add_bench_command(CLI::App& app, int& exit_code) {
  CLI::App* bench = app.add_subcommand("bench", "measure accelerators side by side with Embree");
  bench->require_subcommand(1);

  auto accel_args = std::make_shared<BenchArguments>();
  CLI::App* accel = bench->add_subcommand("accel", "build and trace the same rays with each accelerator");
  add_common_options(accel, *accel_args);
  accel->add_option("--rays", accel_args->rays, "primary, diffuse, shadow or random");
  accel->add_option("--repeat", accel_args->repeat,
                    "timed rounds: every accelerator is built first, then timed once a round in turn; the median run "
                    "and the median of the rounds' ratios to the first accelerator are reported");
  accel->add_flag("--one-at-a-time", accel_args->one_at_a_time,
                  "build, time and drop each accelerator before the next (scenes where they do not all fit at once); "
                  "the ratio to the first is then of the medians");
  accel->add_flag("--packets", accel_args->packets,
                  "primary rays as 2x2 packets (intersect_coherent) where an accelerator has packet traversal");
  accel->add_option("--reference", accel_args->reference,
                    "accelerator the accuracy is measured against (default embree; embree:mode=robust is watertight)");
  accel->add_flag("--reads", accel_args->reads,
                  "one more probed pass counting reads a ray by the accelerator's arrays (nodes and leaves visited)");
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
  add_scene_option(*reorder, reorder_args->scene, SceneKinds::with_worlds, false);
  add_accel_option(*reorder, reorder_args->accel);
  reorder->add_option("--heuristics", reorder_args->heuristics,
                      "comma-separated: none, origin, origin_dir, hph, hph_origin, hph_dir, or paths (no reordering, "
                      "one path at a time: the megakernel); the first is the baseline");
  reorder->add_option("--curve", reorder_args->curve, "morton or hilbert");
  add_spp_option(*reorder, reorder_args->spp);
  add_size_option(*reorder, reorder_args->size);
  add_threads_option(*reorder, reorder_args->threads);
  reorder->add_option("--repeat", reorder_args->repeat,
                      "rounds of every heuristic, interleaved (each heuristic's render of median time is reported)");
  reorder->add_option("--json", reorder_args->json, "write results as JSON");
  add_set_option(*reorder, reorder_args->assignments, "memory.budget=20%");
  reorder->callback([reorder_args, &exit_code] { exit_code = run_reorder(*reorder_args); });

  auto pipeline_args = std::make_shared<PipelineArguments>();
  CLI::App* pipeline = bench->add_subcommand(
      "pipeline", "the megakernel against the wavefront with each reorder heuristic: speed, stage costs, images");
  add_scene_option(*pipeline, pipeline_args->scene, SceneKinds::with_worlds, false);
  add_accel_option(*pipeline, pipeline_args->accel);
  pipeline->add_option("--heuristics", pipeline_args->heuristics,
                       "comma-separated wavefront heuristics: none, origin, origin_dir, hph, hph_origin, hph_dir");
  pipeline->add_option("--threads", pipeline_args->threads, "comma-separated thread counts, each a full set of rows");
  add_spp_option(*pipeline, pipeline_args->spp);
  add_size_option(*pipeline, pipeline_args->size);
  pipeline->add_option("--repeat", pipeline_args->repeat, "renders per row, interleaved (the median is reported)");
  pipeline->add_option("--json", pipeline_args->json, "write results as JSON");
  add_set_option(*pipeline, pipeline_args->assignments, "render.max_depth=8");
  pipeline->callback([pipeline_args, &exit_code] { exit_code = run_pipeline(*pipeline_args); });

  auto sort_args = std::make_shared<SortArguments>();
  CLI::App* sort = bench->add_subcommand(
      "sort", "zsort's flush of scattered rays, apart from any render: keys, sort and gather, ns a ray");
  sort->add_option("--heuristics", sort_args->heuristics, "comma-separated: none, origin, origin_dir, hph, hph_origin, hph_dir");
  sort->add_option("--curves", sort_args->curves, "comma-separated: morton, hilbert");
  sort->add_option("--rays", sort_args->rays, "rays in the buffer (reorder.buffer_rays' default)");
  sort->add_option("--batch-size", sort_args->batch_size, "rays a batch (render.batch_size's default)");
  sort->add_option("--threads", sort_args->threads, "threads of the flush's parallel loops");
  sort->add_option("--repeat", sort_args->repeat, "flushes per row (the median is reported)");
  sort->add_option("--json", sort_args->json, "write results as JSON");
  sort->callback([sort_args, &exit_code] { exit_code = run_sort(*sort_args); });

  auto image_args = std::make_shared<ImageArguments>();
  CLI::App* image = bench->add_subcommand("image", "render the same image with each accelerator, RMSE against the first");
  add_scene_option(*image, image_args->scene, SceneKinds::without_worlds, false);
  add_accel_option(*image, image_args->accel, true, "the first renders the reference image");
  add_spp_option(*image, image_args->spp);
  add_size_option(*image, image_args->size);
  add_threads_option(*image, image_args->threads);
  image->add_flag("--noise", image_args->noise,
                  "also render the first accelerator with render.seed + 1: its RMSE is the Monte Carlo noise");
  image->add_option("--json", image_args->json, "write results as JSON");
  add_set_option(*image, image_args->assignments, "render.max_depth=2");
  image->callback([image_args, &exit_code] { exit_code = run_image(*image_args); });

  auto photon_args = std::make_shared<PhotonArguments>();
  CLI::App* photons = bench->add_subcommand(
      "photons", "photon mapping against a path-traced reference as photons grow: seconds, RMSE, bias");
  add_scene_option(*photons, photon_args->scene, SceneKinds::without_worlds, false);
  photons->add_option("--accel", photon_args->accel, "accelerator type (accel.type)");
  add_spp_option(*photons, photon_args->spp);
  add_size_option(*photons, photon_args->size);
  add_threads_option(*photons, photon_args->threads);
  photons->add_option("--reference-spp", photon_args->reference_spp, "the path-traced reference's samples per pixel");
  photons->add_option("--photons", photon_args->photons, "comma-separated photon counts (k and M suffixes)");
  photons->add_option("--radii", photon_args->radii, "comma-separated photon.radius values at each count (0: auto)");
  photons->add_option("--json", photon_args->json, "write results as JSON");
  add_set_option(*photons, photon_args->assignments, "photon.k=50");
  photons->callback([photon_args, &exit_code] { exit_code = run_photons(*photon_args); });

  add_bench_report_command(*bench, exit_code);
}

}  // namespace wavetrace
