// One scene, accelerator and proxy shared by every heuristic's render.
#include "wavetrace/bench/json_fields.hpp"
#include "wavetrace/bench/reorder_bench.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "wavetrace/bench/render_world.hpp"
#include "wavetrace/memory/process_cpu.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {
namespace {

const StageStats* find_stage(const PipelineRun& run, std::string_view name) {
  for (const StageStats& stage : run.stages) {
    if (stage.name == name) return &stage;
  }
  return nullptr;
}

// One render's figures: its stages' seconds and rays (the photon pass's too), and what
// [memory] counted of trace and approx_hit.
ReorderBenchResult result_of(const ReorderBenchRow& row, const RenderOutput& output) {
  ReorderBenchResult result;
  result.heuristic = row.name();
  result.render_seconds = output.seconds();
  result.closest_mrays_per_s = output.closest_mrays_per_s;
  result.shadow_mrays_per_s = output.any_mrays_per_s;
  const double thread_seconds = output.seconds() * output.run.threads;
  if (const StageStats* paths = find_stage(output.run, "megakernel")) result.rays_traced = paths->rays_in;
  if (const StageStats* trace = find_stage(output.run, "trace")) {
    result.trace_seconds = trace->seconds;
    result.trace_mrays_per_s = trace->mrays_per_s();
    result.rays_traced = trace->rays_in;
    if (trace->pager) {
      result.page_faults = trace->pager->counters.faults;
      result.bytes_loaded = trace->pager->counters.bytes_loaded;
      result.simulated_io_seconds = trace->pager->counters.simulated_io_seconds;
    }
    if (trace->cache) result.cache_misses = trace->cache->counters.misses;
    if (trace->disk) {
      result.disk_faults = trace->disk->counters.faults;
      result.disk_bytes_read = trace->disk->counters.bytes_read;
      result.disk_read_seconds = trace->disk->counters.read_seconds;
      result.disk_wait_seconds = trace->disk->counters.wait_seconds;
      result.disk_reads_in_flight_max = trace->disk->reads_in_flight_max;
      result.disk_prefetched = trace->disk->prefetched;
      result.disk_prefetch_hits = trace->disk->prefetch_hits;
      if (trace->disk->ray_windows.windows > 0) result.disk_pages_per_1000_rays = trace->disk->pages_per_window();
      result.disk_faults_by_part = trace->disk->faults_by_part;
    }
  }
  if (const StageStats* approx = find_stage(output.run, "approx_hit")) {
    result.approx_hit_seconds = approx->seconds;
    result.rays_retired_by_approx_hit = approx->rays_in - approx->rays_out;
    // The proxy's traffic counts too: it is the price of the ordering.
    if (approx->pager && result.page_faults) {
      *result.page_faults += approx->pager->counters.faults;
      *result.bytes_loaded += approx->pager->counters.bytes_loaded;
      *result.simulated_io_seconds += approx->pager->counters.simulated_io_seconds;
    }
    if (approx->cache && result.cache_misses) *result.cache_misses += approx->cache->counters.misses;
  }
  if (const StageStats* zsort = find_stage(output.run, "zsort")) {
    result.sort_seconds = zsort->seconds;
    result.spill = zsort->spill;
  }
  if (output.photons) {
    // The photon pass is traced and reordered as the camera pass is: its stages count too
    // (and [memory]'s counters above already hold both passes').
    result.photon_seconds = output.photons->run.seconds + output.photons->map_seconds;
    if (output.photons->disk) result.photon_disk_faults = output.photons->disk->faults;
    for (const StageStats& stage : output.photons->run.stages) {
      if (stage.name == "trace") {
        result.trace_seconds += stage.seconds;
        result.rays_traced += stage.rays_in;
      }
      if (stage.name == "approx_hit") {
        result.approx_hit_seconds += stage.seconds;
        result.rays_retired_by_approx_hit += stage.rays_in - stage.rays_out;
      }
      if (stage.name == "zsort") result.sort_seconds += stage.seconds;
    }
    result.trace_mrays_per_s = result.trace_seconds > 0.0 ? double(result.rays_traced) / result.trace_seconds * 1e-6 : 0.0;
  }
  result.overhead_share = (result.approx_hit_seconds + result.sort_seconds) / thread_seconds;
  return result;
}

// A row's settings: its heuristic's, and for `paths` the megakernel.
Config row_variant(const Config& config, const ReorderBenchRow& row) {
  Config variant = heuristic_variant(config, row.heuristic);
  if (row.paths) variant.set_value("pipeline.mode", std::string("megakernel"));
  return variant;
}

}  // namespace

ReorderBenchRow parse_reorder_bench_row(const std::string& name) {
  return name == "paths" ? ReorderBenchRow::paths_row() : ReorderBenchRow(parse_reorder_heuristic(name));
}

ReorderBenchReport run_reorder_bench(const Config& config, const std::vector<ReorderBenchRow>& heuristics, int rounds) {
  if (heuristics.empty()) throw ConfigError("--heuristics names no heuristic");
  if (rounds < 1) throw ConfigError("--repeat must be at least 1");
  const RenderPlan base = plan_render(row_variant(config, heuristics.front()));
  if (base.rules.max_depth < 3) {
    throw ConfigError(fmt::format("render.max_depth = {}: the reorder benchmark path traces to depth 3 or more",
                                  base.rules.max_depth));
  }
  bool hit_points = false;
  for (const ReorderBenchRow& row : heuristics) hit_points = hit_points || uses_hit_points(row.heuristic);
  const RenderWorld opened(base, hit_points);
  const Scene& scene = opened.scene();
  const Accelerator* accelerator = &opened.accelerator();
  const Proxy* proxy = opened.proxy();
  FilePager* file_pager = opened.file_pager();
  const LoadedWorld* saved = opened.saved();
  const Camera camera = resolve_camera(base.camera, scene);
  const World world = opened.world();

  ReorderBenchReport report;
  report.scene = scene.name;
  report.triangles = scene.triangle_count;
  if (saved) report.world_bytes = saved->file->file_bytes();
  report.accel = accelerator->name();
  report.curve = to_string(base.reorder.curve);
  // The camera rays' order is the baseline's: the paper generates them along the Z-curve.
  report.image = fmt::format("{}x{}, {} spp, depth {}, camera rays in {} order", base.image.width, base.image.height,
                             base.image.samples_per_pixel, base.rules.max_depth,
                             base.pixel_order == PixelOrder::zcurve ? "Z-curve" : "scanline");
  if (base.integrator == Integrator::photon) {
    report.image += fmt::format(", photon mapping ({} photons, k = {}, {} gathering rays)", base.photon.count,
                                base.photon.k, base.photon.gather_rays);
  }
  if (proxy) {
    const ProxyReport& p = proxy->report();
    report.proxy = fmt::format("{} triangles ({:.4g}% of the scene) by {} on {}; hit overlap {:.1f}%", p.triangles,
                               100.0 * double(p.triangles) / double(report.triangles), to_string(p.method),
                               proxy->accelerator().name(), 100.0 * p.quality.hit_overlap);
    if (p.coarsened_from > 0) *report.proxy += fmt::format(", simplified again from the world's {}", p.coarsened_from);
  }
  report.memory = "off";
  if (base.memory.budget) {
    report.memory = "pager " + config.text("memory.budget") + " of " + std::to_string(base.memory.page_bytes >> 10) +
                    " KiB pages";
    if (file_pager != nullptr) {
      report.memory += fmt::format(" ({}real: {} of {} pages read with O_DIRECT into a {:.1f} MiB pool, "
                                   "placed by {}{})",
                                   base.memory.simulate_beside_file ? "simulated, and " : "", base.scene.source,
                                   file_pager->page_count(), double(file_pager->budget_bytes()) / (1 << 20),
                                   to_string(file_pager->mapping()),
                                   base.memory.page_frames ? ", in frames for walks that read there" : "");
      report.page_count = file_pager->page_count();
    }
  }
  if (base.memory.cache) report.memory += (base.memory.budget ? ", cache " : "cache ") + base.memory.cache->name;

  std::vector<float> first_image;
  // Every round renders every heuristic in the given order. The first sorting render pays the
  // first touch of the sort's buffers and of the pool's extra batches, which later renders
  // find warm in the heap: with one round, a heuristic's place in the list shows in its time.
  std::vector<std::vector<ReorderBenchResult>> rounds_of(heuristics.size());
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t h = 0; h < heuristics.size(); ++h) {
      const RenderPlan plan = plan_render(row_variant(config, heuristics[h]));
      const ProcessCpuTime cpu_before = read_process_cpu_time();
      const RenderOutput output = render_image(plan, world, camera);
      const ProcessCpuTime cpu = read_process_cpu_time() - cpu_before;
      report.threads = output.run.threads;

      ReorderBenchResult result = result_of(heuristics[h], output);
      result.cpu_user_seconds = cpu.user_seconds;
      result.cpu_system_seconds = cpu.system_seconds;
      if (first_image.empty()) first_image = output.image;
      result.image_identical = output.image == first_image;
      rounds_of[h].push_back(std::move(result));
    }
  }
  report.rounds = rounds;
  for (std::vector<ReorderBenchResult>& results : rounds_of) {
    // The render of median time, whole: its stage seconds and counters belong together.
    std::sort(results.begin(), results.end(),
              [](const ReorderBenchResult& a, const ReorderBenchResult& b) { return a.render_seconds < b.render_seconds; });
    ReorderBenchResult median = results[(results.size() - 1) / 2];
    median.image_identical =
        std::all_of(results.begin(), results.end(), [](const ReorderBenchResult& r) { return r.image_identical; });
    report.results.push_back(std::move(median));
  }
  return report;
}

nlohmann::json to_json(const ReorderBenchReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const ReorderBenchResult& r : report.results) {
    nlohmann::json parts = nlohmann::json::object();
    for (const auto& [part, faults] : r.disk_faults_by_part) parts[part] = faults;
    nlohmann::json spill = nullptr;
    if (r.spill) {
      spill = {{"bytes_written", r.spill->bytes_written}, {"bytes_read", r.spill->bytes_read},
               {"seconds", r.spill->seconds}, {"runs", r.spill->runs}};
    }
    results.push_back({{"heuristic", r.heuristic},
                       {"render_seconds", r.render_seconds},
                       {"cpu_user_seconds", r.cpu_user_seconds},
                       {"cpu_system_seconds", r.cpu_system_seconds},
                       {"photon_seconds", r.photon_seconds},
                       {"trace_seconds", r.trace_seconds},
                       {"trace_mrays_per_s", r.trace_mrays_per_s},
                       {"closest_mrays_per_s", r.closest_mrays_per_s},
                       {"shadow_mrays_per_s", r.shadow_mrays_per_s},
                       {"approx_hit_seconds", r.approx_hit_seconds},
                       {"sort_seconds", r.sort_seconds},
                       {"overhead_share", r.overhead_share},
                       {"rays_traced", r.rays_traced},
                       {"rays_retired_by_approx_hit", r.rays_retired_by_approx_hit},
                       {"page_faults", json_or_null(r.page_faults)},
                       {"bytes_loaded", json_or_null(r.bytes_loaded)},
                       {"simulated_io_seconds", json_or_null(r.simulated_io_seconds)},
                       {"cache_misses", json_or_null(r.cache_misses)},
                       {"disk_faults", json_or_null(r.disk_faults)},
                       {"photon_disk_faults", json_or_null(r.photon_disk_faults)},
                       {"disk_bytes_read", json_or_null(r.disk_bytes_read)},
                       {"disk_read_seconds", json_or_null(r.disk_read_seconds)},
                       {"disk_wait_seconds", json_or_null(r.disk_wait_seconds)},
                       {"disk_reads_in_flight_max", json_or_null(r.disk_reads_in_flight_max)},
                       {"disk_prefetched", json_or_null(r.disk_prefetched)},
                       {"disk_prefetch_hits", json_or_null(r.disk_prefetch_hits)},
                       {"disk_pages_per_1000_rays", json_or_null(r.disk_pages_per_1000_rays)},
                       {"disk_faults_by_part", parts},
                       {"spill", spill},
                       {"image_identical", r.image_identical}});
  }
  return {{"scene", {{"source", report.scene}, {"triangles", report.triangles}}},
          {"accel", report.accel},
          {"curve", report.curve},
          {"image", report.image},
          {"threads", report.threads},
          {"rounds", report.rounds},
          {"proxy", json_or_null(report.proxy)},
          {"memory", report.memory},
          {"world_bytes", report.world_bytes},
          {"page_count", report.page_count},
          {"results", results}};
}

std::string to_table(const ReorderBenchReport& report) {
  std::string table = fmt::format("{}: {} triangles; {} on {}; {} curve; {} threads; memory {}{}\n", report.scene,
                                  report.triangles, report.image, report.accel, report.curve, report.threads, report.memory,
                                  report.rounds > 1 ? fmt::format("; the median of {} rounds", report.rounds) : "");
  if (report.proxy) table += "proxy: " + *report.proxy + "\n";
  const bool disk = !report.results.empty() && report.results.front().disk_faults.has_value();
  const bool photons = !report.results.empty() && report.results.front().photon_seconds > 0.0;
  table += fmt::format("{:<11} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8} {:>9} {:>10} {:>9} {:>11} {:>11} "
                       "{:>9} {:>10}",
                       "heuristic", "render s", "cpu usr s", "cpu sys s", "trace s", "Mr/s/thr", "closest", "shadow",
                       "approx s", "sort s", "overhead", "faults", "sim I/O s", "misses", "vs first", "speedup",
                       "identical");
  table += disk ? fmt::format(" {:>11} {:>9} {:>9} {:>9} {:>11} {:>10} {:>10} {:>10} {:>10} {:>9}", "disk faults",
                              "disk MB", "read s", "wait s", "disk vs 1st", "rays/page", "pages/1k", "read ahead",
                              "ahead hits", "in flight")
                : "";
  table += photons ? fmt::format(" {:>9}{}\n", "photon s", disk ? fmt::format(" {:>13}", "photon faults") : "") : "\n";
  const ReorderBenchResult* first = report.results.empty() ? nullptr : &report.results.front();
  const auto optional = [](const auto& value, const char* format) {
    return value ? fmt::format(fmt::runtime(format), *value) : std::string("-");
  };
  const auto ratio = [](const std::optional<std::uint64_t>& base, const std::optional<std::uint64_t>& value) {
    return base && value && *value > 0 ? fmt::format("{:.2f}x", double(*base) / double(*value)) : std::string("-");
  };
  for (const ReorderBenchResult& r : report.results) {
    table += fmt::format("{:<11} {:>9.3f} {:>9.2f} {:>9.2f} {:>9.3f} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.3f} {:>8.3f} {:>8.1f}% {:>10} "
                         "{:>9} {:>11} {:>11} {:>8.2f}x {:>10}",
                         r.heuristic, r.render_seconds, r.cpu_user_seconds, r.cpu_system_seconds, r.trace_seconds,
                         r.trace_mrays_per_s, r.closest_mrays_per_s, r.shadow_mrays_per_s, r.approx_hit_seconds,
                         r.sort_seconds, 100.0 * r.overhead_share, optional(r.page_faults, "{}"),
                         optional(r.simulated_io_seconds, "{:.1f}"), optional(r.cache_misses, "{}"),
                         ratio(first->page_faults, r.page_faults), first->render_seconds / r.render_seconds,
                         r.image_identical ? "yes" : "NO");
    if (disk) {
      table += fmt::format(" {:>11} {:>9.1f} {:>9.2f} {:>9.2f} {:>11} {:>10.0f} {:>10} {:>10} {:>10} {:>9}",
                           optional(r.disk_faults, "{}"),
                           double(r.disk_bytes_read.value_or(0)) * 1e-6, r.disk_read_seconds.value_or(0.0),
                           r.disk_wait_seconds.value_or(0.0), ratio(first->disk_faults, r.disk_faults),
                           double(r.rays_traced) / double(std::max<std::size_t>(report.page_count, 1)),
                           optional(r.disk_pages_per_1000_rays, "{:.1f}"), optional(r.disk_prefetched, "{}"),
                           optional(r.disk_prefetch_hits, "{}"), optional(r.disk_reads_in_flight_max, "{}"));
    }
    if (photons) {
      table += fmt::format(" {:>9.3f}", r.photon_seconds);
      if (disk) table += fmt::format(" {:>13}", optional(r.photon_disk_faults, "{}"));
    }
    table += "\n";
  }
  table += "Mr/s/thr: trace's rays per busy thread-second (closest: camera and bounce rays; shadow: any-hit rays)\n"
           "vs first: the first heuristic's page faults over this one's; speedup: its render seconds over this one's\n";
  if (disk) {
    table += "disk: real faults of trace (pages read from the world file with O_DIRECT), their bytes and measured read\n"
             "seconds (inside render s); wait s: trace's threads waiting for pages (their own reads included);\n"
             "rays/page: rays traced per page of the world file; pages/1k: distinct pages 1,000 consecutive traced rays touch;\n"
             "read ahead: of the faults, pages trace's look-ahead read before trace reached them (memory.look_ahead);\n"
             "ahead hits: of those, pages trace read before they were evicted; in flight: the most reads under way at once\n";
  }
  if (photons) {
    table += "photon s: photon mapping's photon pass and maps (within render s)";
    table += disk ? "; photon faults: the disk faults of the photon pass (within disk faults)\n" : "\n";
  }
  return table;
}

}  // namespace wavetrace
