// `wavetrace render`: config and flags to a plan, scene and accelerator to an image.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <new>
#include <optional>

#include <fmt/format.h>

#include "wavetrace/accel/registry.hpp"
#include "app/command_options.hpp"
#include "app/commands.hpp"
#include "app/image_output.hpp"
#include "app/progress_line.hpp"
#include "app/render_report.hpp"
#include "wavetrace/distribute/chunk_exchange.hpp"
#include "wavetrace/distribute/chunk_probe.hpp"
#include "wavetrace/distribute/shared_render.hpp"
#include "wavetrace/distribute/mpi_session.hpp"
#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/accelerator_spec.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_file.hpp"

namespace wavetrace {
namespace {

struct RenderArguments {
  std::string scene;
  std::string accel;
  std::optional<int> spp;  // unset: render.spp from the config
  std::string size;
  std::optional<int> threads;  // unset: render.threads from the config
  std::string config_file;
  std::vector<std::string> assignments;
  std::string out = "out/render.exr";
  std::string stats;
};

Config build_config(const RenderArguments& args) {
  Config config;
  if (!args.config_file.empty()) config.load_file(args.config_file);
  if (!args.scene.empty()) config.set_value("scene.source", args.scene);
  if (!args.accel.empty()) apply_accelerator_spec(config, args.accel);
  if (args.spp) config.set_value("render.spp", std::int64_t{*args.spp});
  if (args.threads) config.set_value("render.threads", std::int64_t{*args.threads});
  if (!args.size.empty()) set_image_size(config, args.size);
  for (const std::string& assignment : args.assignments) config.set(assignment);
  return config;
}

// Renders through the pipeline and writes the image, the report and the stats.
// Under mpirun every rank renders its share and only rank 0 writes and reports.
int finish_render(const RenderArguments& args, const MpiSession& session, const RenderPlan& plan, const Scene& scene,
                  const World& world, const Camera& camera, RenderPhases measured, const AccelChoice* choice,
                  const RankSetup& rank_setup) {
  ProgressLine progress(stderr);
  const bool show_progress = progress.enabled() && session.rank() == 0;
  const auto on_progress =
      show_progress ? [&](const Progress& p) { progress.update(p); } : std::function<void(const Progress&)>();
  std::optional<DistributedRender> distributed;
  if (session.distributed()) distributed = render_shared(session, plan, world, camera, on_progress, rank_setup);
  const RenderOutput output = distributed ? std::move(distributed->output) : render_image(plan, world, camera, on_progress);
  if (show_progress) progress.finish();
  if (session.rank() != 0) return 0;
  measured.after_render_bytes = read_resident_memory().current_bytes;
  measured.huge_page_bytes = anonymous_huge_page_bytes();
  measured.peak_rss_bytes = read_resident_memory().peak_bytes;

  write_exr(args.out, plan.image.width, plan.image.height, output.image);
  const std::string preview = preview_path_for(args.out);
  write_png_preview(preview, plan.image.width, plan.image.height, output.image);

  const RenderFacts facts{scene, world.accelerator, plan, output, args.out, world.proxy, measured, choice,
                          distributed ? &*distributed : nullptr};
  fmt::print("{}: {} triangles, {} vertices{}\n", scene.name, scene.triangle_count, scene.vertex_count,
             scene.cleanup.degenerate_dropped ? fmt::format(", {} degenerate dropped", scene.cleanup.degenerate_dropped)
                                              : std::string());
  fmt::print("{}", render_table(facts));
  fmt::print("wrote {} and {}\n", args.out, preview);
  if (!args.stats.empty()) {
    std::ofstream file(args.stats);
    file << render_stats_json(facts).dump(2) << "\n";
    if (!file) throw std::runtime_error(fmt::format("{}: could not write stats", args.stats));
  }
  return 0;
}

int render_in_session(const RenderArguments& args, const MpiSession& session) {
  const Config config = build_config(args);
  const RenderPlan plan = plan_render(config);
  // What was being done, so that running out of memory says where (and not "bad_alloc").
  std::string activity;
  try {
    // A data-parallel rank answers for its own chunks: the load gives each chunk's pages back
    // once checked, so that it never holds the whole world.
    const bool answers_a_part = session.distributed() && plan.distribute.mode == DistributeMode::data;
    BuiltWorld built(plan, &activity, answers_a_part ? CheckedPages::given_back : CheckedPages::kept);
    if (const ResolvedAccelerator* resolved = built.resolution(); resolved != nullptr && session.rank() == 0) {
      if (const std::string line = resolution_summary(*resolved); !line.empty()) fmt::print("{}\n", line);
    }
    RenderPhases measured;
    measured.load_seconds = built.phases().load_seconds;
    measured.after_load_bytes = built.phases().after_load_bytes;
    measured.after_build_bytes = built.phases().after_build_bytes;
    if (const SectionFile* file = built.world_file(); file != nullptr) {
      measured.world_holding = file->pager() != nullptr ? "paged" : std::string(to_string(file->holding()));
      measured.world_holding_note = file->holding_note();
      if (!measured.world_holding_note.empty() && session.rank() == 0) fmt::print("{}\n", measured.world_holding_note);
    }
    const RenderPlan& done = built.plan();
    activity = fmt::format("rendering {}x{} at {} spp", done.image.width, done.image.height, done.image.samples_per_pixel);
    const AccelChoice* choice =
        built.resolution() != nullptr && built.resolution()->choice ? &*built.resolution()->choice : nullptr;
    // Data mode: this rank owns a run of the chunks and asks the others about theirs.
    std::unique_ptr<ChunkExchange> exchange;
    if (session.distributed() && done.distribute.mode == DistributeMode::data) {
      ChunkSet* chunks = built.chunk_set();
      if (chunks == nullptr) {
        throw ConfigError(fmt::format("distribute.mode = data needs a chunked world ({} is not): a scene of more "
                                      "than build.chunk_triangles, or a world file built with chunks",
                                      built.world().accelerator.name()));
      }
      ChunkSharing sharing{done.distribute.balance, done.distribute.replicate, {}};
      if (sharing.balance == DistributeBalance::rays || sharing.replicate > 0.0) {
        sharing.rays_due = probe_rays_due(*chunks, built.camera(), float(done.image.width) / float(done.image.height),
                                          128, [&] { built.drop_resident_world_pages(); });
      }
      exchange = std::make_unique<ChunkExchange>(session, *chunks, sharing);
    }
    RankSetup rank_setup{exchange.get()};
    if (exchange) {
      // The load gave each chunk's pages back once checked; what it touched after the last
      // chunk goes back too, so that the rank holds the chunks it answers for, and the render's
      // peak is measured apart from the load's.
      rank_setup.load_peak_resident_bytes = read_resident_memory().peak_bytes;
      built.drop_resident_world_pages();
      reset_peak_resident_memory();
    }
    return finish_render(args, session, done, built.scene(), built.world(), built.camera(), measured, choice,
                         rank_setup);
  } catch (const std::bad_alloc&) {
    throw std::runtime_error(fmt::format("out of memory {} ({:.2f} GB resident at most, {:.2f} GB available now)",
                                         activity, double(read_resident_memory().peak_bytes) * 1e-9,
                                         double(available_memory_bytes()) * 1e-9));
  }
}

int run_render(const RenderArguments& args) {
  const MpiSession session;
  try {
    return render_in_session(args, session);
  } catch (const std::exception& error) {
    if (!session.distributed()) throw;
    // The other ranks may be waiting on this one: say which failed and why, and end them all.
    fmt::print(stderr, "wavetrace: error: rank {} of {} ({}): {}\n", session.rank(), session.ranks(), session.host(),
               error.what());
    session.abort(1);
  }
}

}  // namespace

void add_render_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<RenderArguments>();
  CLI::App* command = app.add_subcommand("render", "path-trace an image through the stage pipeline");
  add_scene_option(*command, args->scene, SceneKinds::with_worlds);
  add_accel_option(*command, args->accel);
  add_spp_option(*command, args->spp);
  add_size_option(*command, args->size);
  add_threads_option(*command, args->threads);
  add_config_option(*command, args->config_file);
  add_set_option(*command, args->assignments);
  command->add_option("--out", args->out, "OpenEXR output; a PNG preview is written beside it");
  command->add_option("--stats", args->stats, "write run statistics as JSON");
  command->callback([args, &exit_code] { exit_code = run_render(*args); });
}

}  // namespace wavetrace
