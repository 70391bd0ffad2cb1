// Stage table and stats JSON of a render.
#include "app/render_report.hpp"

#include <fmt/format.h>

#include "wavetrace/bench/json_fields.hpp"
#include "wavetrace/stages/trace.hpp"

namespace wavetrace {

nlohmann::json bounds_json(const Bounds3& bounds) {
  return {{"min", {bounds.lower.x, bounds.lower.y, bounds.lower.z}},
          {"max", {bounds.upper.x, bounds.upper.y, bounds.upper.z}}};
}

nlohmann::json pager_json(const PagerStats& pager) {
  return {{"page_bytes", pager.page_bytes},
          {"budget_bytes", pager.budget_bytes},
          {"accesses", pager.counters.accesses},
          {"faults", pager.counters.faults},
          {"bytes_loaded", pager.counters.bytes_loaded},
          {"simulated_io_seconds", pager.counters.simulated_io_seconds}};
}

nlohmann::json cache_json(const CacheStats& cache) {
  return {{"preset", cache.geometry.name},
          {"line_bytes", cache.geometry.line_bytes},
          {"capacity_bytes", cache.geometry.capacity_bytes},
          {"ways", cache.geometry.ways},
          {"accesses", cache.counters.accesses},
          {"misses", cache.counters.misses}};
}

std::string memory_lines(const std::vector<StageStats>& stages) {
  std::string lines;
  for (const StageStats& stage : stages) {
    const double rays = double(std::max<std::uint64_t>(stage.rays_in, 1));
    if (stage.pager) {
      const PagerCounters& c = stage.pager->counters;
      lines += fmt::format("{} pager: {:.1f} MiB pages, budget {:.1f} MiB: {} reads, {} faults, {:.1f} MB loaded, "
                           "{:.3f} s simulated I/O (not in the measured time)\n",
                           stage.name, double(stage.pager->page_bytes) / (1 << 20),
                           double(stage.pager->budget_bytes) / (1 << 20), c.accesses, c.faults,
                           double(c.bytes_loaded) * 1e-6, c.simulated_io_seconds);
    }
    if (stage.disk) {
      const DiskCounters& c = stage.disk->counters;
      const std::string frames =
          stage.disk->frames > 0 ? fmt::format(", {} of them in frames", stage.disk->frames) : std::string();
      lines += fmt::format("{} disk: {} KiB pages, pool {:.1f} MiB{}: {} real faults ({} by reads no probe announced), "
                           "{:.1f} MB read in {:.3f} s (O_DIRECT, in the measured time), {:.3f} s waited for pages, "
                           "up to {} reads at once\n",
                           stage.name, stage.disk->page_bytes >> 10, double(stage.disk->budget_bytes) / (1 << 20),
                           frames, c.faults, c.unannounced, double(c.bytes_read) * 1e-6, c.read_seconds, c.wait_seconds,
                           stage.disk->reads_in_flight_max);
      if (stage.disk->prefetched > 0) {
        lines += fmt::format("{} disk: {} of those pages read ahead by its look-ahead, {} of them used before evicted\n",
                             stage.name, stage.disk->prefetched, stage.disk->prefetch_hits);
      }
      if (!stage.disk->faults_by_part.empty()) {
        std::string parts;
        for (const auto& [part, faults] : stage.disk->faults_by_part) {
          parts += fmt::format("{}{} {}", parts.empty() ? "" : ", ", part, faults);
        }
        lines += fmt::format("{} disk faults by part: {}\n", stage.name, parts);
      }
      if (stage.disk->ray_windows.windows > 0) {
        lines += fmt::format("{} disk: {:.1f} distinct pages touched per {} consecutive rays ({} windows)\n", stage.name,
                             stage.disk->pages_per_window(), TraceStage::kRayWindow, stage.disk->ray_windows.windows);
      }
    }
    if (stage.spill) {
      lines += fmt::format("{} spill: {} runs on disk, {:.1f} MB written, {:.1f} MB read, {:.3f} s of I/O\n", stage.name,
                           stage.spill->runs, double(stage.spill->bytes_written) * 1e-6,
                           double(stage.spill->bytes_read) * 1e-6, stage.spill->seconds);
    }
    if (stage.cache) {
      const CacheGeometry& g = stage.cache->geometry;
      const CacheCounters& c = stage.cache->counters;
      lines += fmt::format("{} cache {} ({} KiB, {}-way, {} B lines, one per thread): {} line reads, {} misses "
                           "({:.2f}%), {:.2f} misses per ray\n",
                           stage.name, g.name, g.capacity_bytes >> 10, g.ways, g.line_bytes, c.accesses, c.misses,
                           100.0 * double(c.misses) / double(std::max<std::uint64_t>(c.accesses, 1)),
                           double(c.misses) / rays);
    }
  }
  return lines;
}

// A stage's rays and seconds, the start of its entry in either pass.
nlohmann::json stage_json(const StageStats& stage) {
  return {{"name", stage.name},
          {"rays_in", stage.rays_in},
          {"rays_out", stage.rays_out},
          {"seconds", stage.seconds},
          {"mrays_per_s", stage.mrays_per_s()}};
}

nlohmann::json cpu_json(const ProcessCpuTime& cpu) {
  return {{"user", cpu.user_seconds}, {"system", cpu.system_seconds}};
}

nlohmann::json spill_json(const SpillCounters& spill) {
  return {{"bytes_written", spill.bytes_written}, {"bytes_read", spill.bytes_read}, {"seconds", spill.seconds}, {"runs", spill.runs}};
}

nlohmann::json disk_parts_json(const DiskStats& disk) {
  nlohmann::json parts = nlohmann::json::object();
  for (const auto& [part, faults] : disk.faults_by_part) parts[part] = faults;
  return parts;
}

nlohmann::json proxy_json(const Proxy& proxy) {
  const ProxyReport& report = proxy.report();
  const auto quality = [](const std::optional<ProxyQuality>& q) -> nlohmann::json {
    if (!q) return nullptr;
    return {{"hit_agreement", q->hit_agreement}, {"hit_overlap", q->hit_overlap},
            {"mean_distance_error", q->mean_distance_error}};
  };
  return {{"method", to_string(report.method)},
          {"triangles", report.triangles},
          {"simplify_seconds", report.simplify_seconds},
          {"build_seconds", report.build_seconds},
          {"accel", proxy.accelerator().name()},
          {"quality", quality(report.quality)},
          {"cluster_quality", quality(report.cluster_quality)},
          {"stochastic_quality", quality(report.stochastic_quality)},
          {"coarsened_from", report.coarsened_from > 0 ? nlohmann::json(report.coarsened_from) : nlohmann::json(nullptr)},
          {"quality_against", report.judged_against_saved ? "saved proxy" : "scene"}};
}

nlohmann::json render_stats_json(const RenderFacts& facts) {
  const MemoryReport memory = facts.accelerator.memory();
  const BuildReport build = facts.accelerator.build();
  const double triangles = double(facts.scene.triangle_count);
  nlohmann::json stages = nlohmann::json::array();
  for (const StageStats& stage : facts.output.run.stages) {
    nlohmann::json entry = stage_json(stage);
    if (stage.pager) entry["pager"] = pager_json(*stage.pager);
    if (stage.disk) {
      entry["disk"] = {{"mapping", to_string(stage.disk->mapping)},
                       {"frames", stage.disk->frames},
                       {"page_bytes", stage.disk->page_bytes},
                       {"budget_bytes", stage.disk->budget_bytes},
                       {"faults", stage.disk->counters.faults},
                       {"unannounced_faults", stage.disk->counters.unannounced},
                       {"bytes_read", stage.disk->counters.bytes_read},
                       {"read_seconds", stage.disk->counters.read_seconds},
                       {"wait_seconds", stage.disk->counters.wait_seconds},
                       {"reads_in_flight_max", stage.disk->reads_in_flight_max},
                       {"prefetched", stage.disk->prefetched},
                       {"prefetch_hits", stage.disk->prefetch_hits},
                       {"faults_by_part", disk_parts_json(*stage.disk)},
                       {"pages_per_1000_rays", json_or_null(stage.disk->ray_windows.windows > 0
                                                                ? std::optional(stage.disk->pages_per_window())
                                                                : std::nullopt)}};
    }
    if (stage.cache) entry["cache"] = cache_json(*stage.cache);
    if (stage.spill) entry["spill"] = spill_json(*stage.spill);
    stages.push_back(entry);
  }
  nlohmann::json hit_rates = nlohmann::json::array();
  for (const DepthHitRate& rate : facts.output.hit_rates) {
    hit_rates.push_back({{"depth", rate.depth}, {"rays", rate.rays}, {"hits", rate.hits}, {"hit_rate", rate.rate()}});
  }
  nlohmann::json render = {{"seconds", facts.output.run.seconds},
                            {"threads", facts.output.run.threads},
                            {"cpu_seconds", cpu_json(facts.output.run.cpu)}};
  render["stages"] = facts.plan.stages;
  render["mode"] = to_string(facts.plan.pipeline.mode);
  // The camera pass's, with photons; batches: the pool's high-water mark, each of
  // render.batch_size rays with their hits.
  render["rays_in_memory"] = {{"budget", facts.plan.pipeline.rays_in_flight},
                              {"peak", facts.output.run.peak_rays_in_core},
                              {"batches", facts.output.run.batches_allocated},
                              {"batch_rays", facts.plan.pipeline.batch_size}};
  render["reorder"] = {{"heuristic", to_string(facts.plan.reorder.heuristic)},
                       {"curve", to_string(facts.plan.reorder.curve)},
                       {"buffer_rays", facts.plan.reorder.buffer_rays},
                       {"sort_seconds", facts.output.sort_seconds}};
  nlohmann::json stats = {
      {"scene",
       {{"source", facts.scene.name},
        {"triangles", facts.scene.triangle_count},
        {"vertices", facts.scene.vertex_count},
        {"bounds", bounds_json(facts.scene.bounds)},
        {"degenerate_dropped", facts.scene.cleanup.degenerate_dropped},
        {"load_seconds", facts.phases.load_seconds}}},
      {"accel",
       {{"type", facts.accelerator.name()},
        {"isa", facts.accelerator.isa()},
        {"bytes", memory.total()},
        {"bytes_per_triangle", double(memory.total()) / triangles},
        {"parts", {{"hierarchy", memory.hierarchy}, {"geometry", memory.geometry}, {"other", memory.other}}},
        {"build_seconds", build.seconds},
        {"build_peak_accounted_bytes", build.peak_bytes},
        {"build_phases", build_phases_json(build.phases)},
        {"build_notes", facts.accelerator.build_notes()},
        {"auto", facts.accel_choice ? to_json(*facts.accel_choice) : nlohmann::json(nullptr)}}},
      {"stages", stages},
      {"hit_rates", hit_rates},
      {"render", render},
      {"image",
       {{"width", facts.plan.image.width},
        {"height", facts.plan.image.height},
        {"spp", facts.plan.image.samples_per_pixel},
        {"path", facts.image_path}}},
  };
  if (facts.proxy != nullptr) stats["proxy"] = proxy_json(*facts.proxy);
  render["integrator"] = facts.plan.integrator == Integrator::photon ? "photon" : "path";
  if (const std::optional<PhotonPassReport>& photons = facts.output.photons) {
    nlohmann::json photon_stages = nlohmann::json::array();
    for (const StageStats& stage : photons->run.stages) {
      nlohmann::json entry = stage_json(stage);  // no [memory] counts: the camera pass reports both passes'
      if (stage.spill) entry["spill"] = spill_json(*stage.spill);
      photon_stages.push_back(entry);
    }
    stats["photons"] = {{"emitted", photons->emitted},
                        {"global_photons", photons->global_photons},
                        {"caustic_photons", photons->caustic_photons},
                        {"k", facts.plan.photon.k},
                        {"radius", photons->radius},
                        {"gather_rays", facts.plan.photon.gather_rays},
                        {"seconds", photons->run.seconds},
                        {"cpu_seconds", cpu_json(photons->run.cpu)},
                        {"map_seconds", photons->map_seconds},
                        {"precomputed", photons->precomputed},
                        {"stages", photon_stages}};
    if (photons->disk) {
      stats["photons"]["disk"] = {{"faults", photons->disk->faults},
                                  {"bytes_read", photons->disk->bytes_read},
                                  {"read_seconds", photons->disk->read_seconds},
                                  {"wait_seconds", photons->disk->wait_seconds}};
    }
  }
  stats["render"] = render;
  const RenderPhases& measured = facts.phases;
  stats["memory"] = {{"peak_rss_bytes", measured.peak_rss_bytes},
                     {"after_load_bytes", measured.after_load_bytes},
                     {"after_build_bytes", measured.after_build_bytes},
                     {"after_render_bytes", measured.after_render_bytes},
                     {"peak_rss_bytes_per_triangle", double(measured.peak_rss_bytes) / triangles},
                     {"huge_page_bytes", measured.huge_page_bytes}};
  if (!measured.world_holding.empty()) {
    stats["memory"]["world"] = {{"holding", measured.world_holding}, {"note", measured.world_holding_note}};
  }
  if (facts.distributed != nullptr) stats["distribute"] = distribute_json(*facts.distributed, facts.plan);
  return stats;
}

nlohmann::json distribute_json(const DistributedRender& render, const RenderPlan& plan) {
  nlohmann::json ranks = nlohmann::json::array();
  for (const RankReport& rank : render.ranks) {
    ranks.push_back({{"rank", rank.rank},
                     {"host", rank.host},
                     {"ranges", rank.ranges},
                     {"camera_rays", rank.camera_rays},
                     {"rays_traced", rank.rays_traced},
                     {"render_seconds", rank.render_seconds},
                     {"cpu_seconds", cpu_json(rank.cpu)},
                     {"wait_seconds", rank.wait_seconds},
                     {"peak_resident_bytes", rank.peak_resident_bytes}});
    if (plan.distribute.mode == DistributeMode::data) {
      const ChunkTraffic& traffic = rank.traffic;
      ranks.back()["load_peak_resident_bytes"] = rank.load_peak_resident_bytes;
      ranks.back()["exchange"] = {{"chunks_owned", traffic.chunks_owned},
                                  {"triangles_owned", traffic.triangles_owned},
                                  {"bytes_owned", traffic.bytes_owned},
                                  {"chunks_copied", traffic.chunks_copied},
                                  {"triangles_copied", traffic.triangles_copied},
                                  {"queries_sent", traffic.queries_sent},
                                  {"rays_sent", traffic.rays_sent},
                                  {"bytes_sent", traffic.bytes_sent},
                                  {"queries_answered", traffic.queries_answered},
                                  {"rays_answered", traffic.rays_answered},
                                  {"wait_seconds", traffic.wait_seconds},
                                  {"rounds_suspended", traffic.rounds_suspended}};
    }
  }
  return {{"mode", to_string(plan.distribute.mode)},
          {"ranks", render.ranks.size()},
          {"range_rays", render.range_rays},
          {"replicate", plan.distribute.replicate},
          {"balance", to_string(plan.distribute.balance)},
          {"wall_seconds", render.wall_seconds},
          {"rays_traced", render.rays_traced()},
          {"mrays_per_s", double(render.rays_traced()) / render.wall_seconds * 1e-6},
          {"per_rank", ranks}};
}

namespace {

// One row per stage of a run: rays in and out, busy seconds, share of the run's thread-seconds.
std::string stage_rows(const PipelineRun& run) {
  const double thread_seconds = run.seconds * run.threads;
  std::string rows = fmt::format("{:<15} {:>14} {:>14} {:>10} {:>8} {:>12}\n", "stage", "rays in", "rays out",
                                 "seconds", "share", "Mrays/s/thr");
  for (const StageStats& stage : run.stages) {
    rows += fmt::format("{:<15} {:>14} {:>14} {:>10.3f} {:>7.1f}% {:>12.2f}\n", stage.name, stage.rays_in,
                        stage.rays_out, stage.seconds, 100.0 * stage.seconds / thread_seconds, stage.mrays_per_s());
  }
  return rows;
}

}  // namespace

std::string render_table(const RenderFacts& facts) {
  const PipelineRun& run = facts.output.run;
  const double thread_seconds = run.seconds * run.threads;
  std::string table;
  if (const std::optional<PhotonPassReport>& photons = facts.output.photons) {
    table += fmt::format("photon pass: {} photons emitted in {:.3f} s; {} landed ({} by specular paths: the caustic "
                         "map), maps built in {:.3f} s ({} irradiance estimates precomputed); estimates of k = {} "
                         "within {:.4g}\n",
                         photons->emitted, photons->run.seconds, photons->global_photons, photons->caustic_photons,
                         photons->map_seconds, photons->precomputed, facts.plan.photon.k, photons->radius);
    table += stage_rows(photons->run);
    if (photons->disk) {
      table += fmt::format("photon pass disk: {} real faults, {:.1f} MB read in {:.3f} s, {:.3f} s waited for pages "
                           "(within the camera pass's trace disk line, which counts the whole render)\n",
                           photons->disk->faults, double(photons->disk->bytes_read) * 1e-6, photons->disk->read_seconds,
                           photons->disk->wait_seconds);
    }
    table += "camera pass:\n";
  }
  table += stage_rows(run);
  double traced = 0.0;
  for (const StageStats& stage : run.stages) {
    if (stage.name == "trace" || stage.name == "megakernel") traced = double(stage.rays_in);
  }
  if (!facts.output.hit_rates.empty()) {
    table += "hit rate by depth (camera 0, bounces 1+):";
    for (const DepthHitRate& rate : facts.output.hit_rates) {
      table += fmt::format(" {}: {:.1f}%", rate.depth, 100.0 * rate.rate());
    }
    table += "\n";
  }
  if (facts.plan.reorder.heuristic != ReorderHeuristic::none) {
    table += fmt::format("reorder: {} keys on a {} curve, buffer of {} rays; sorting alone {:.3f} s\n",
                         to_string(facts.plan.reorder.heuristic), to_string(facts.plan.reorder.curve),
                         facts.plan.reorder.buffer_rays, facts.output.sort_seconds);
  }
  if (facts.proxy != nullptr) {
    const ProxyReport& proxy = facts.proxy->report();
    const std::string from =
        proxy.coarsened_from > 0 ? fmt::format(" (simplified again from the world's {})", proxy.coarsened_from) : "";
    table += fmt::format("proxy: {} triangles{} by {} in {:.2f} s (+{:.2f} s {} build); hits overlap the {}'s on "
                         "{:.1f}% of test rays (agree on {:.1f}%)\n",
                         proxy.triangles, from, to_string(proxy.method), proxy.simplify_seconds, proxy.build_seconds,
                         facts.proxy->accelerator().name(), proxy.judged_against_saved ? "saved proxy" : "scene",
                         100.0 * proxy.quality.hit_overlap, 100.0 * proxy.quality.hit_agreement);
  }
  const MemoryReport memory = facts.accelerator.memory();
  const BuildReport build = facts.accelerator.build();
  table += fmt::format("render ({}): {:.3f} s wall on {} threads ({:.3f} thread-seconds; the process's CPU {:.3f} s user, "
                       "{:.3f} s system), {:.2f} Mrays/s traced\n",
                       to_string(facts.plan.pipeline.mode), run.seconds, run.threads, thread_seconds, run.cpu.user_seconds,
                       run.cpu.system_seconds, traced / run.seconds * 1e-6);
  if (const DistributedRender* shared = facts.distributed) {
    table += fmt::format("distributed ({} mode, {} ranks, ranges of {} camera rays): {:.3f} s wall, {:.2f} Mrays/s "
                         "traced by all; the table above is rank 0's\n",
                         to_string(facts.plan.distribute.mode), shared->ranks.size(), shared->range_rays,
                         shared->wall_seconds, double(shared->rays_traced()) / shared->wall_seconds * 1e-6);
    for (const RankReport& rank : shared->ranks) {
      table += fmt::format("  rank {} on {}: {} ranges, {} camera rays, {} traced in {:.3f} s (CPU {:.3f} s user, {:.3f} s "
                           "system; waited {:.3f} s for ranges), {:.2f} GB resident at most\n",
                           rank.rank, rank.host, rank.ranges, rank.camera_rays, rank.rays_traced, rank.render_seconds,
                           rank.cpu.user_seconds, rank.cpu.system_seconds, rank.wait_seconds,
                           double(rank.peak_resident_bytes) * 1e-9);
      if (facts.plan.distribute.mode == DistributeMode::data) {
        const ChunkTraffic& traffic = rank.traffic;
        table += fmt::format("    owns {} chunks ({} triangles, {:.1f} MB) and answers {} of others' itself ({} triangles); sent {} "
                             "rays in {} queries ({:.1f} MB with the answers it gave), answered {} rays of others' in {} "
                             "queries; its rounds waited {:.3f} s for answers ({} of them suspended, the thread tracing on); {:.2f} GB resident at most while loading (every "
                             "chunk checked)\n",
                             traffic.chunks_owned, traffic.triangles_owned, double(traffic.bytes_owned) * 1e-6,
                             traffic.chunks_copied,
                             traffic.triangles_copied, traffic.rays_sent, traffic.queries_sent,
                             double(traffic.bytes_sent) * 1e-6, traffic.rays_answered, traffic.queries_answered,
                             traffic.wait_seconds, traffic.rounds_suspended, double(rank.load_peak_resident_bytes) * 1e-9);
      }
    }
  }
  const std::string isa = facts.accelerator.isa();
  table += fmt::format("accel {}{}: {:.1f} MB, {:.1f} bytes/triangle (hierarchy {:.1f}, geometry {:.1f}), built in {:.3f} s\n",
                       facts.accelerator.name(), isa.empty() ? "" : " (" + isa + " walks)", double(memory.total()) * 1e-6,
                       double(memory.total()) / double(facts.scene.triangle_count),
                       double(memory.hierarchy) / double(facts.scene.triangle_count),
                       double(memory.geometry) / double(facts.scene.triangle_count), build.seconds);
  if (const std::string notes = facts.accelerator.build_notes(); !notes.empty()) {
    table += fmt::format("accel {}: {}\n", facts.accelerator.name(), notes);
  }
  const RenderPhases& measured = facts.phases;
  table += fmt::format(
      "memory (resident, from the OS): peak {:.2f} GB ({:.1f} bytes/triangle); after load ({:.1f} s) {:.2f} GB, after "
      "build {:.2f} GB, after render {:.2f} GB\n",
      double(measured.peak_rss_bytes) * 1e-9, double(measured.peak_rss_bytes) / double(facts.scene.triangle_count),
      measured.load_seconds, double(measured.after_load_bytes) * 1e-9, double(measured.after_build_bytes) * 1e-9,
      double(measured.after_render_bytes) * 1e-9);
  if (!measured.world_holding.empty()) {
    table += fmt::format("world file {}; {:.2f} GB of the process on 2 MiB pages\n",
                         measured.world_holding_note.empty() ? measured.world_holding : measured.world_holding_note,
                         double(measured.huge_page_bytes) * 1e-9);
  }
  table += memory_lines(run.stages);
  if (facts.output.memory_unobserved) table += "memory: " + *facts.output.memory_unobserved + "\n";
  if (facts.output.rejected_contributions > 0) {
    table += fmt::format("warning: {} non-finite film contributions were dropped\n", facts.output.rejected_contributions);
  }
  return table;
}

}  // namespace wavetrace
