// Builds, times and checks each accelerator against the Embree reference.
#include "wavetrace/bench/json_fields.hpp"
#include "wavetrace/bench/accel_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/memory/read_tally.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/pipeline/tracing_arena.hpp"

namespace wavetrace {
namespace {

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

void compare(const RaySet& rays, const std::vector<std::unique_ptr<HitBatch>>& hits,
             const std::vector<std::unique_ptr<HitBatch>>& reference, float diagonal, AccelBenchResult& result) {
  std::size_t agree = 0, both = 0, same_primitive = 0, total = 0;
  double error_sum = 0.0, error_max = 0.0;
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
      ++total;
      const bool hit = hits[b]->is_hit(i), expected = reference[b]->is_hit(i);
      agree += hit == expected;
      if (!hit || !expected || rays.any_hit()) continue;
      ++both;
      same_primitive += hits[b]->primitive[i] == reference[b]->primitive[i];
      const double error = std::fabs(double(hits[b]->t[i]) - double(reference[b]->t[i])) / diagonal;
      error_sum += error;
      error_max = std::max(error_max, error);
    }
  }
  result.hit_agreement = total ? double(agree) / double(total) : 1.0;
  if (!rays.any_hit()) {
    result.prim_agreement = both ? double(same_primitive) / double(both) : 1.0;
    result.t_error_max = error_max;
    result.t_error_mean = both ? error_sum / double(both) : 0.0;
  }
}

// For a lossy accelerator on rays that start on a surface: the rays again with tmin raised
// past its stated error, traced by it and by the reference (see AccelBenchResult).
void measure_agreement_beyond_error(const RaySet& rays, const Accelerator& reference, const Accelerator& accelerator,
                                    const std::vector<std::unique_ptr<HitBatch>>& hits,
                                    const std::vector<std::unique_ptr<HitBatch>>& reference_hits, AccelBenchResult& result) {
  if (!result.vertex_error_max || !(*result.vertex_error_max > 0.0) || rays.kind == RaySetKind::primary ||
      rays.kind == RaySetKind::random) {
    return;
  }
  const float start = static_cast<float>(kBeyondErrorFactor * *result.vertex_error_max);
  RaySet later{rays.kind, {}};
  std::size_t self_hits = 0;
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    const RayBatch& batch = *rays.batches[b];
    auto copy = std::make_unique<RayBatch>(batch.capacity());
    for (std::size_t i = 0; i < batch.count; ++i) {
      copy->copy_ray(i, batch, i);
      copy->tmin[i] = std::max(batch.tmin[i], start);
      const bool own = hits[b]->is_hit(i) && hits[b]->t[i] < start;
      const bool theirs = reference_hits[b]->is_hit(i) && reference_hits[b]->t[i] < start;
      self_hits += own && !theirs;
    }
    copy->count = batch.count;
    later.batches.push_back(std::move(copy));
  }
  AccelBenchResult beyond;
  compare(later, trace_ray_set(accelerator, later), trace_ray_set(reference, later), 1.0f, beyond);
  result.beyond_error_start = start;
  result.beyond_error_hit_agreement = beyond.hit_agreement;
  result.beyond_error_prim_agreement = beyond.prim_agreement;
  result.self_hits = double(self_hits) / double(std::max<std::size_t>(rays.count(), 1));
}

// Each result's speed against the first's. Interleaved, run k of each was timed in the same
// round, so the rounds' ratios pair runs that shared the machine's state of that moment and
// their median is the figure; one at a time, the ratio of the medians.
void set_ratios_to_first(AccelBenchReport& report) {
  if (report.results.empty()) return;
  const AccelBenchResult& first = report.results.front();
  for (AccelBenchResult& r : report.results) {
    r.vs_first_runs.clear();
    if (report.interleaved) {
      for (std::size_t run = 0; run < r.mrays_per_s_runs.size() && run < first.mrays_per_s_runs.size(); ++run) {
        r.vs_first_runs.push_back(r.mrays_per_s_runs[run] / first.mrays_per_s_runs[run]);
      }
      r.vs_first = median(r.vs_first_runs);
    } else {
      r.vs_first = first.mrays_per_s > 0 ? r.mrays_per_s / first.mrays_per_s : 0.0;
    }
  }
}

}  // namespace

AcceleratorSpec parse_accelerator_spec(const std::string& text, const Config& base) {
  Config config = base;
  apply_accelerator_spec(config, text);
  return {text, accelerator_options(config), accel_goal(config), std::nullopt};
}

void resolve_accelerator_spec(AcceleratorSpec& spec, const Scene& scene, const Config& base) {
  if (!spec.goal.automatic && !pixel_epsilon_applies(spec.options, spec.goal)) return;
  if (scene.streamed()) throw ConfigError(fmt::format("--accel {}: needs the scene's mesh", spec.label));
  const RenderPlan plan = plan_render(base);
  const MeshTriangleSource source(scene.mesh, scene.object_starts);
  const ResolvedAccelerator resolved = resolve_accelerator(spec.options, spec.goal, source,
                                                           resolve_camera(plan.camera, scene), plan.image, false);
  spec.options = resolved.options;
  spec.auto_choice = resolved.choice;
  spec.label = resolved.choice ? fmt::format("{} ({})", spec.label, resolved.choice->spec)
                               : fmt::format("{} ({:.4g})", spec.label, spec.options.hmq.epsilon);
  spec.goal = AccelGoal{};
}

// For a lossy accelerator: the distance of each hit point (origin + t direction) from the
// point with the same barycentrics on the mesh's triangle, against the largest vertex move.
void measure_surface_error(const TriangleMesh& mesh, const Accelerator& accelerator, const RaySet& rays,
                           const std::vector<std::unique_ptr<HitBatch>>& hits, AccelBenchResult& result) {
  const std::optional<TriangleMesh> represented = accelerator.represented_mesh(mesh);
  if (!represented) return;
  double moved = 0.0;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    moved = std::max(moved, double(glm::length(represented->positions[v] - mesh.positions[v])));
  }
  double worst = 0.0;
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    const RayBatch& batch = *rays.batches[b];
    const HitBatch& hit = *hits[b];
    for (std::size_t i = 0; i < batch.count; ++i) {
      if (!hit.is_hit(i)) continue;
      const glm::dvec3 origin(batch.origin_x[i], batch.origin_y[i], batch.origin_z[i]);
      const glm::dvec3 direction(batch.direction_x[i], batch.direction_y[i], batch.direction_z[i]);
      const glm::uvec3& corners = mesh.triangles[hit.primitive[i]];
      const double u = hit.u[i], v = hit.v[i];
      const glm::dvec3 on_mesh = (1.0 - u - v) * glm::dvec3(mesh.positions[corners.x]) +
                                 u * glm::dvec3(mesh.positions[corners.y]) + v * glm::dvec3(mesh.positions[corners.z]);
      worst = std::max(worst, glm::length(origin + double(hit.t[i]) * direction - on_mesh));
    }
  }
  result.surface_error_max = worst;
  result.vertex_error_max = moved;
}

// A probed pass per budget (or one cache-only pass), each with a fresh pool and caches.
std::vector<MemoryRun> memory_runs(const Accelerator& accelerator, const RaySet& rays, const AccelBenchRequest& request,
                                   int threads) {
  std::vector<std::string> budgets = request.budgets;
  if (budgets.empty()) budgets.push_back(request.memory.budget ? std::string("config") : std::string());
  std::vector<MemoryRun> runs;
  for (const std::string& label : budgets) {
    MemoryPlan plan = request.memory;
    if (!label.empty() && label != "config") plan.budget = parse_memory_budget(label);
    MemoryObservation observation(plan, accelerator.memory_spans(), threads);
    const auto start = std::chrono::steady_clock::now();
    trace_ray_set_probed(accelerator, rays, observation.observers());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<StageStats> stages(1);
    stages[0].name = "trace";
    observation.report(stages);
    MemoryRun run;
    run.budget = label;
    for (const auto& span : accelerator.memory_spans()) run.world_bytes += span.size();
    run.pager = stages[0].pager;
    run.cache = stages[0].cache;
    run.instrumented_mrays_per_s = double(rays.count()) / seconds * 1e-6;
    runs.push_back(std::move(run));
  }
  return runs;
}

AccelBenchReport run_accel_bench(const Scene& scene, const AccelBenchRequest& request) {
  TracingArena arena(request.threads);
  AccelBenchReport report;
  report.scene = scene.name;
  report.triangles = scene.triangle_count;
  report.rays = to_string(request.rays);
  report.reference = request.reference.label;
  report.threads = arena.threads();
  report.repeats = request.repeats;
  // Interleaved rounds need every subject held at once; a lone subject has nothing to alternate with.
  report.interleaved = !request.one_at_a_time && (request.world != nullptr ? 1 : request.accelerators.size()) > 1;
  report.packets = request.packets && request.rays == RaySetKind::primary;
  report.memory_observed = request.memory.enabled() || !request.budgets.empty();
  const float diagonal = scene.bounds.diagonal();
  const bool has_mesh = !scene.mesh.triangles.empty();
  if (request.world != nullptr && !has_mesh) report.reference = "the world itself (it holds no mesh)";

  arena.execute([&] {
    const std::unique_ptr<Accelerator> built_reference =
        has_mesh ? make_accelerator(scene.mesh, request.reference.options) : nullptr;
    const Accelerator* reference = built_reference ? built_reference.get() : request.world;
    const RaySet rays = make_ray_set(request.rays, scene, *reference, request.count, kDefaultBatchCapacity,
                                     request.world_lights);
    report.ray_count = rays.count();
    const auto reference_hits = trace_ray_set(*reference, rays);
    std::size_t reference_hit_count = 0;
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) reference_hit_count += reference_hits[b]->is_hit(i);
    }
    report.reference_hit_rate = double(reference_hit_count) / double(std::max<std::size_t>(1, report.ray_count));

    // A subject from its build (or the world's load) to its report: built, timed, checked.
    struct Subject {
      AccelBenchResult result;
      std::unique_ptr<Accelerator> built;
      const Accelerator* accelerator = nullptr;
      std::vector<std::unique_ptr<HitBatch>> hits;  // made once, written by every run
    };
    const auto prepare = [&](std::size_t index) {
      Subject subject;
      AccelBenchResult& result = subject.result;
      if (request.world != nullptr) {
        result.label = request.world_label;
        result.build = request.world->build();
        result.build.seconds = request.world_load_seconds;  // the world's load stands for its build
      } else {
        const AcceleratorSpec& spec = request.accelerators[index];
        result.label = spec.label;
        result.auto_choice = spec.auto_choice;
        // The build's peak resident memory, from the OS: the peak window starts here, so it
        // holds what the process already had (scene, rays, reference, the subjects built
        // before it) plus the build's own.
        const bool windowed = reset_peak_resident_memory();
        const std::size_t resident_before = read_resident_memory().current_bytes;
        subject.built = build_world_accelerator(scene, spec.options);
        const std::size_t peak = read_resident_memory().peak_bytes;
        if (windowed) result.build_peak_rss_above_start_bytes = peak > resident_before ? peak - resident_before : 0;
        result.build = subject.built->build();
      }
      subject.accelerator = subject.built ? subject.built.get() : request.world;
      subject.hits = make_hit_batches(rays);
      result.memory = subject.accelerator->memory();
      result.bytes_per_triangle = double(result.memory.total()) / double(scene.triangle_count);
      result.build_notes = subject.accelerator->build_notes();
      result.isa = subject.accelerator->isa();
      return subject;
    };
    const auto time_run = [&](Subject& subject) {
      const auto start = std::chrono::steady_clock::now();
      trace_ray_set(*subject.accelerator, rays, subject.hits, report.packets);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      subject.result.mrays_per_s_runs.push_back(double(report.ray_count) / seconds * 1e-6);
    };
    const auto finish = [&](Subject& subject) {
      AccelBenchResult& result = subject.result;
      const Accelerator& accelerator = *subject.accelerator;
      result.mrays_per_s = median(result.mrays_per_s_runs);
      compare(rays, subject.hits, reference_hits, diagonal, result);
      if (!rays.any_hit() && has_mesh) measure_surface_error(scene.mesh, accelerator, rays, subject.hits, result);
      if (has_mesh) measure_agreement_beyond_error(rays, *reference, accelerator, subject.hits, reference_hits, result);
      result.probed = accelerator.probed();
      if (report.memory_observed && result.probed) result.memory_runs = memory_runs(accelerator, rays, request, report.threads);
      if (request.count_reads && result.probed) {
        ReadTally tally(accelerator.memory_spans(), std::size_t(std::max(report.threads, 1)));
        MemoryObservers observers;
        observers.tally = &tally;
        trace_ray_set_probed(accelerator, rays, observers);
        result.reads_by_array = tally.totals();
        for (const auto& array : tally.arrays()) result.array_bytes.push_back(array.size());
      }
      report.results.push_back(std::move(result));
      subject = {};  // its structure goes before the next one is built
    };

    const std::size_t subjects = request.world != nullptr ? 1 : request.accelerators.size();
    const int runs = std::max(1, request.repeats);
    if (report.interleaved) {
      std::vector<Subject> all;
      for (std::size_t index = 0; index < subjects; ++index) all.push_back(prepare(index));
      // A round untimed first: this machine's speed climbs over a process's first seconds.
      // Then the order turns each round (A B C, C B A, ...), so that a steady drift favours
      // no accelerator over a pair of rounds.
      for (Subject& subject : all) trace_ray_set(*subject.accelerator, rays, subject.hits, report.packets);
      for (int run = 0; run < runs; ++run) {
        if (run % 2 == 0) {
          for (Subject& subject : all) time_run(subject);
        } else {
          for (auto subject = all.rbegin(); subject != all.rend(); ++subject) time_run(*subject);
        }
      }
      for (Subject& subject : all) finish(subject);
    } else {
      for (std::size_t index = 0; index < subjects; ++index) {
        Subject subject = prepare(index);
        trace_ray_set(*subject.accelerator, rays, subject.hits, report.packets);  // untimed, as above
        for (int run = 0; run < runs; ++run) time_run(subject);
        finish(subject);
      }
    }
    set_ratios_to_first(report);
  });
  return report;
}

// Absent (null) where the accelerator cannot be observed or nothing was asked: never zeros.
nlohmann::json memory_runs_json(const AccelBenchReport& report, const AccelBenchResult& r) {
  if (!report.memory_observed || !r.probed) return nullptr;
  nlohmann::json runs = nlohmann::json::array();
  for (const MemoryRun& run : r.memory_runs) {
    nlohmann::json entry = {{"budget", run.budget},
                            {"world_bytes", run.world_bytes},
                            {"instrumented_mrays_per_s", run.instrumented_mrays_per_s}};
    if (run.pager) entry["pager"] = {{"page_bytes", run.pager->page_bytes},
                                     {"budget_bytes", run.pager->budget_bytes},
                                     {"accesses", run.pager->counters.accesses},
                                     {"faults", run.pager->counters.faults},
                                     {"bytes_loaded", run.pager->counters.bytes_loaded},
                                     {"simulated_io_seconds", run.pager->counters.simulated_io_seconds}};
    if (run.cache) entry["cache"] = {{"preset", run.cache->geometry.name},
                                     {"line_bytes", run.cache->geometry.line_bytes},
                                     {"capacity_bytes", run.cache->geometry.capacity_bytes},
                                     {"ways", run.cache->geometry.ways},
                                     {"accesses", run.cache->counters.accesses},
                                     {"misses", run.cache->counters.misses}};
    runs.push_back(entry);
  }
  return runs;
}

nlohmann::json to_json(const AccelBenchReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const AccelBenchResult& r : report.results) {
    results.push_back({{"accel", r.label},
                       {"bytes", r.memory.total()},
                       {"bytes_per_triangle", r.bytes_per_triangle},
                       {"parts", {{"hierarchy", r.memory.hierarchy}, {"geometry", r.memory.geometry}, {"other", r.memory.other}}},
                       {"build_seconds", r.build.seconds},
                       {"build_peak_accounted_bytes", r.build.peak_bytes},
                       {"build_phases", build_phases_json(r.build.phases)},
                       {"build_peak_rss_above_start_bytes", r.build_peak_rss_above_start_bytes},
                       {"build_notes", r.build_notes},
                       {"isa", r.isa},
                       {"mrays_per_s", r.mrays_per_s},
                       {"mrays_per_s_runs", r.mrays_per_s_runs},
                       {"vs_first", r.vs_first},
                       {"vs_first_runs", r.vs_first_runs},
                       {"hit_agreement", r.hit_agreement},
                       {"prim_agreement", json_or_null(r.prim_agreement)},
                       {"surface_error_max", json_or_null(r.surface_error_max)},
                       {"vertex_error_max", json_or_null(r.vertex_error_max)},
                       {"beyond_error_start", json_or_null(r.beyond_error_start)},
                       {"beyond_error_hit_agreement", json_or_null(r.beyond_error_hit_agreement)},
                       {"beyond_error_prim_agreement", json_or_null(r.beyond_error_prim_agreement)},
                       {"self_hits", json_or_null(r.self_hits)},
                       {"t_error_max", json_or_null(r.t_error_max)},
                       {"t_error_mean", json_or_null(r.t_error_mean)},
                       {"memory_runs", memory_runs_json(report, r)},
                       {"reads_by_array", r.reads_by_array},
                       {"array_bytes", r.array_bytes},
                       {"auto", r.auto_choice ? to_json(*r.auto_choice) : nlohmann::json(nullptr)}});
  }
  return {{"scene", {{"source", report.scene}, {"triangles", report.triangles}}},
          {"reference", report.reference},
          {"rays", {{"kind", report.rays}, {"count", report.ray_count}, {"reference_hit_rate", report.reference_hit_rate}}},
          {"threads", report.threads},
          {"repeats", report.repeats},
          {"interleaved", report.interleaved},
          {"packets", report.packets},
          {"results", results}};
}

std::string to_csv(const AccelBenchReport& report) {
  std::string csv =
      "scene,triangles,rays,count,threads,accel,isa,bytes,bytes_per_triangle,hierarchy,geometry,other,build_seconds,"
      "build_peak_accounted_bytes,build_peak_rss_above_start_bytes,mrays_per_s,hit_agreement,prim_agreement,t_error_max,t_error_mean\n";
  const auto optional = [](const std::optional<double>& v) { return v ? fmt::format("{:.9g}", *v) : std::string(); };
  for (const AccelBenchResult& r : report.results) {
    csv += fmt::format("{},{},{},{},{},{},{},{},{:.3f},{},{},{},{:.4f},{},{},{:.4f},{:.9g},{},{},{}\n", report.scene,
                       report.triangles, report.rays, report.ray_count, report.threads, r.label, r.isa, r.memory.total(),
                       r.bytes_per_triangle, r.memory.hierarchy, r.memory.geometry, r.memory.other, r.build.seconds,
                       r.build.peak_bytes, r.build_peak_rss_above_start_bytes, r.mrays_per_s, r.hit_agreement, optional(r.prim_agreement),
                       optional(r.t_error_max), optional(r.t_error_mean));
  }
  return csv;
}

// Reads a ray by world array: for a BVH the nodes and leaves (blocks, records) it visits.
std::string reads_table(const AccelBenchReport& report) {
  const double rays = double(std::max<std::size_t>(report.ray_count, 1));
  std::string table = "\nreads a ray, by array of the accelerator (its memory spans in order, with their MB):\n";
  for (const AccelBenchResult& r : report.results) {
    if (r.reads_by_array.empty()) {
      table += fmt::format("{:<24} cannot be observed: no counters\n", r.label);
      continue;
    }
    std::string cells;
    for (std::size_t array = 0; array < r.array_bytes.size(); ++array) {
      cells += fmt::format("{}{:.1f} MB: {:.2f}", array == 0 ? "" : " | ", double(r.array_bytes[array]) * 1e-6,
                           double(r.reads_by_array[array]) / rays);
    }
    if (r.reads_by_array.back() > 0) cells += fmt::format(" | elsewhere: {:.2f}", double(r.reads_by_array.back()) / rays);
    table += fmt::format("{:<24} {}\n", r.label, cells);
  }
  return table;
}

std::string memory_table(const AccelBenchReport& report) {
  const double rays = double(std::max<std::size_t>(report.ray_count, 1));
  std::string table = fmt::format("\nsimulated memory (pager and cache counts are exact with 1 thread):\n{:<24} {:>7} {:>9} {:>10} "
                                  "{:>10} {:>10} {:>11} {:>10} {:>12} {:>11}\n",
                                  "accel", "budget", "world MB", "budget MB", "faults", "faults/ray", "loaded MB",
                                  "sim I/O s", "misses/ray", "instr Mr/s");
  for (const AccelBenchResult& r : report.results) {
    if (!r.probed) {
      table += fmt::format("{:<24} cannot be observed: no counters\n", r.label);
      continue;
    }
    for (const MemoryRun& run : r.memory_runs) {
      const auto& pager = run.pager;
      table += fmt::format(
          "{:<24} {:>7} {:>9.1f} {:>10} {:>10} {:>10} {:>11} {:>10} {:>12} {:>11.3f}\n", r.label,
          run.budget.empty() ? "-" : run.budget, double(run.world_bytes) * 1e-6,
          pager ? fmt::format("{:.1f}", double(pager->budget_bytes) * 1e-6) : "-",
          pager ? fmt::format("{}", pager->counters.faults) : "-",
          pager ? fmt::format("{:.4f}", double(pager->counters.faults) / rays) : "-",
          pager ? fmt::format("{:.1f}", double(pager->counters.bytes_loaded) * 1e-6) : "-",
          pager ? fmt::format("{:.2f}", pager->counters.simulated_io_seconds) : "-",
          run.cache ? fmt::format("{:.3f}", double(run.cache->counters.misses) / rays) : "-",
          run.instrumented_mrays_per_s);
    }
  }
  return table;
}

std::string to_table(const AccelBenchReport& report) {
  std::string table = fmt::format(
      "{}: {} triangles; {} {} rays{} ({:.1f}% hit the reference, {}); {} threads; median of {}\n", report.scene,
      report.triangles, report.ray_count, report.rays, report.packets ? " as 2x2 packets" : "",
      100.0 * report.reference_hit_rate, report.reference, report.threads,
      report.interleaved ? fmt::format("{} rounds, each accelerator once a round in turn", report.repeats)
                         : fmt::format("{} runs, one accelerator at a time", report.repeats));
  table += fmt::format("{:<24} {:<7} {:>9} {:>8} {:>8} {:>8} {:>9} {:>11} {:>8} {:>10} {:>11} {:>10} {:>10} {:>10}\n", "accel",
                       "isa", "MB", "B/tri", "hier", "geom", "build s", "peak RSS MB", "Mrays/s", "vs first", "its rounds",
                       "hit agr", "prim agr", "t err max");
  const double triangles = double(report.triangles);
  for (const AccelBenchResult& r : report.results) {
    const auto [lowest, highest] = std::minmax_element(r.vs_first_runs.begin(), r.vs_first_runs.end());
    const std::string rounds = r.vs_first_runs.empty() ? "-" : fmt::format("{:.2f}-{:.2f}", *lowest, *highest);
    table += fmt::format("{:<24} {:<7} {:>9.1f} {:>8.1f} {:>8.1f} {:>8.1f} {:>9.3f} {:>11.1f} {:>8.2f} {:>9.2f}x {:>11} {:>9.4f}% {:>9} {:>10}\n",
                         r.label, r.isa.empty() ? "-" : r.isa, double(r.memory.total()) * 1e-6, r.bytes_per_triangle,
                         double(r.memory.hierarchy) / triangles, double(r.memory.geometry) / triangles, r.build.seconds,
                         double(r.build_peak_rss_above_start_bytes) * 1e-6, r.mrays_per_s, r.vs_first, rounds,
                         100.0 * r.hit_agreement,
                         r.prim_agreement ? fmt::format("{:.4f}%", 100.0 * *r.prim_agreement) : std::string("-"),
                         r.t_error_max ? fmt::format("{:.2e}", *r.t_error_max) : std::string("-"));
  }
  for (const AccelBenchResult& r : report.results) {
    if (!r.build_notes.empty()) table += fmt::format("{}: {}\n", r.label, r.build_notes);
  }
  for (const AccelBenchResult& r : report.results) {
    if (!r.surface_error_max) continue;
    table += fmt::format("{}: hit points lie at most {:.3g} from the mesh's triangles (vertices moved at most {:.3g})\n",
                         r.label, *r.surface_error_max, *r.vertex_error_max);
  }
  for (const AccelBenchResult& r : report.results) {
    if (!r.beyond_error_start) continue;
    table += fmt::format("{}: rays started {:.3g} out ({}x its vertex error): hit agreement {:.4f}%{}; {:.4f}% of rays "
                         "hit its own surface before that and the reference's not\n",
                         r.label, *r.beyond_error_start, kBeyondErrorFactor, 100.0 * *r.beyond_error_hit_agreement,
                         r.beyond_error_prim_agreement
                             ? fmt::format(", primitive agreement {:.4f}%", 100.0 * *r.beyond_error_prim_agreement)
                             : std::string(),
                         100.0 * *r.self_hits);
  }
  if (report.memory_observed) table += memory_table(report);
  if (std::any_of(report.results.begin(), report.results.end(), [](const auto& r) { return !r.reads_by_array.empty(); })) {
    table += reads_table(report);
  }
  return table;
}

}  // namespace wavetrace
