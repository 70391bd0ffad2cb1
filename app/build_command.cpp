// `wavetrace build`: a scene built once into a world file (.wtw) that render, info and the
// benchmarks map and trace without rebuilding.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/proxy/proxy_by_chunks.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/json_fields.hpp"
#include "app/command_options.hpp"
#include "app/commands.hpp"
#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/accelerator_spec.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_file.hpp"

namespace wavetrace {
namespace {

struct BuildArguments {
  std::string scene;
  std::string accel;
  std::optional<int> threads;  // unset: render.threads from the config
  std::string config_file;
  std::vector<std::string> assignments;
  bool proxy = false;
  std::string out;
  std::string stats;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Before a build of hours stops for want of disk at its end: the file's size by its type's
// measured bytes per triangle (registry.cpp; the mesh's, for a type rebuilt from it when
// loaded) against the free space where it goes.
void check_world_file_space(const std::string& out, double estimated_bytes) {
  const std::filesystem::path directory = std::filesystem::absolute(out).parent_path();
  std::error_code error;
  const std::filesystem::space_info space = std::filesystem::space(directory, error);
  if (error) throw ConfigError(fmt::format("--out {}: {}: {}", out, directory.string(), error.message()));
  if (estimated_bytes > double(space.available)) {
    throw ConfigError(fmt::format("--out {}: the world needs about {:.2f} GB and {} has {:.2f} GB free", out,
                                  estimated_bytes * 1e-9, directory.string(), double(space.available) * 1e-9));
  }
}

int run_build(const BuildArguments& args) {
  Config config;
  if (!args.config_file.empty()) config.load_file(args.config_file);
  if (!args.scene.empty()) config.set_value("scene.source", args.scene);
  if (!args.accel.empty()) apply_accelerator_spec(config, args.accel);
  if (args.threads) config.set_value("render.threads", std::int64_t{*args.threads});
  for (const std::string& assignment : args.assignments) config.set(assignment);
  if (!is_world_file(args.out)) throw ConfigError(fmt::format("--out {}: a world file is named *.wtw", args.out));
  RenderPlan plan = plan_render(config);
  if (is_world_file(plan.scene.source)) throw ConfigError(fmt::format("{} is already a world", plan.scene.source));
  // A world is saved to be paged: proxy.share = auto takes the paper's share (a render in core
  // simplifies it again).
  if (plan.proxy.share_by_holding) plan.proxy.share = ProxyOptions::kPagedShare;
  // Every parallel phase, ours and Embree's, on at most --threads threads: the builds run in
  // TBB's default arena, which would otherwise take every core.
  std::optional<tbb::global_control> thread_limit;
  if (plan.pipeline.threads > 0) {
    thread_limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(plan.pipeline.threads));
  }
  const bool with_proxy = args.proxy || plan.needs_proxy();
  // A world that builds in chunks is written chunk by chunk as it is built and never held
  // whole, so that it may be larger than memory; its proxy, when one is wanted, is simplified
  // chunk by chunk too (proxy_by_chunks.hpp).
  const auto streams_to_file = [&](const std::string& type) { return saves_structure(type) && builds_in_chunks(type); };

  // As render does: an accelerator holding its own geometry is built from a streamed scene
  // (never whole) unless a proxy simplified from the whole mesh is wanted.
  const auto load_start = std::chrono::steady_clock::now();
  const bool streams = streams_to_file(plan.accelerator.type);
  SceneForWorld loaded = load_scene_for_world(plan, with_proxy && !streams, streams);
  Scene& scene = loaded.scene;
  plan.accelerator = loaded.accelerator.options;
  const std::string& type = plan.accelerator.type;
  check_world_file_space(args.out, double(scene.triangle_count) * (saves_structure(type)
                                                                       ? estimated_bytes_per_triangle(plan.accelerator)
                                                                       : kWholeMeshBytesPerTriangle));
  if (const std::string line = resolution_summary(loaded.accelerator); !line.empty()) fmt::print("{}\n", line);
  // The world records what was built, not what chose it.
  record_built_accelerator(config, plan);
  WorldBuildInfo info;
  info.scene_seconds = seconds_since(load_start);
  const auto build_start = std::chrono::steady_clock::now();
  SectionWriter out(args.out);
  std::optional<ProxyByChunks> proxy_pieces;
  if (with_proxy && streams_to_file(type)) proxy_pieces.emplace(plan.proxy);
  ChunkStream stream{out, kWorldAcceleratorPrefix};
  if (proxy_pieces) {
    stream.observe = [&](std::size_t chunk, std::size_t first, const TriangleMesh& mesh, const Accelerator& built) {
      proxy_pieces->add(chunk, first, mesh, built);
    };
  }
  const std::unique_ptr<Accelerator> accelerator =
      build_world_accelerator(scene, plan.accelerator, streams_to_file(type) ? &stream : nullptr);
  const LightSampler lights = represented_lights(scene, *accelerator);
  std::unique_ptr<Proxy> proxy;
  if (proxy_pieces && !proxy_pieces->empty()) {
    proxy = proxy_pieces->finish(scene.bounds);
  } else if (with_proxy) {
    // Built whole (a scene of one chunk, or a type that does not build in chunks): from the
    // whole mesh, which a streamed scene of one chunk gives again.
    const TriangleMesh whole = scene.streamed() ? scene.stream->extract(0, scene.triangle_count) : TriangleMesh{};
    proxy = std::make_unique<Proxy>(scene.streamed() ? whole : scene.mesh, plan.proxy, *accelerator);
  }
  // A type traced in place no longer needs the mesh (bvh's face sets have their own copy
  // or keep the mesh they point into; rebuilt types save it).
  if (holds_own_geometry(type)) scene.release_mesh();
  info.build_seconds = seconds_since(build_start);

  const auto save_start = std::chrono::steady_clock::now();
  info.peak_rss_bytes = read_resident_memory().peak_bytes;
  save_world(out, scene, lights, *accelerator, type, proxy.get(), config, info);
  const double save_seconds = seconds_since(save_start);
  const std::uintmax_t file_bytes = std::filesystem::file_size(args.out);
  const std::size_t peak = read_resident_memory().peak_bytes;

  const double triangles = double(std::max<std::size_t>(scene.triangle_count, 1));
  fmt::print("{}: {} triangles; {} ({})\n", scene.name, scene.triangle_count, type,
             !saves_structure(type)                ? "rebuilt from the saved geometry when loaded"
             : streams_to_file(type) && scene.triangle_count > plan.accelerator.chunk_triangles
                 ? "saved in place, each chunk as it was built"
                 : "saved in place");
  fmt::print("scene {:.2f} s, build {:.2f} s, save {:.2f} s; peak resident {:.2f} GB\n", info.scene_seconds,
             info.build_seconds, save_seconds, double(peak) * 1e-9);
  if (const BuildPhases phases = accelerator->build().phases; !phases.empty()) {
    std::string line;
    for (const auto& [name, seconds] : phases.entries()) line += fmt::format("{}{} {:.2f}", line.empty() ? "" : ", ", name, seconds);
    fmt::print("build phases (s; chunk.* summed over chunks): {}\n", line);
  }
  fmt::print("wrote {}: {:.3f} GB, {:.2f} bytes/triangle (in memory: {:.2f}){}\n", args.out, double(file_bytes) * 1e-9,
             double(file_bytes) / triangles, double(accelerator->memory().total()) / triangles,
             proxy ? fmt::format("; proxy of {} triangles", proxy->report().triangles) : std::string());
  if (!args.stats.empty()) {
    const nlohmann::json stats = {{"scene", {{"source", plan.scene.source}, {"name", scene.name},
                                             {"triangles", scene.triangle_count}}},
                                  {"accel", type},
                                  {"threads", tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)},
                                  {"scene_seconds", info.scene_seconds},
                                  {"build_seconds", info.build_seconds},
                                  {"build_phases", build_phases_json(accelerator->build().phases)},
                                  {"save_seconds", save_seconds},
                                  {"peak_rss_bytes", peak},
                                  {"file_bytes", file_bytes},
                                  {"file_bytes_per_triangle", double(file_bytes) / triangles},
                                  {"memory_bytes", accelerator->memory().total()},
                                  {"proxy_triangles", proxy ? proxy->report().triangles : 0}};
    std::ofstream file(args.stats);
    file << stats.dump(2) << "\n";
    if (!file) throw std::runtime_error(fmt::format("{}: could not write stats", args.stats));
  }
  return 0;
}

}  // namespace

void add_build_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<BuildArguments>();
  CLI::App* command = app.add_subcommand("build", "build a scene's world once and save it to a world file (.wtw)");
  add_scene_option(*command, args->scene, SceneKinds::without_worlds);
  add_accel_option(*command, args->accel);
  add_threads_option(*command, args->threads);
  add_config_option(*command, args->config_file);
  add_set_option(*command, args->assignments);
  command->add_flag("--proxy", args->proxy,
                    "also simplify and save the proxy that hit-point reordering needs (always when reorder.heuristic needs it)");
  command->add_option("--out", args->out, "the world file to write (*.wtw)")->required();
  command->add_option("--stats", args->stats, "write the build's figures as JSON");
  command->callback([args, &exit_code] { exit_code = run_build(*args); });
}

}  // namespace wavetrace
