// `wavetrace bench reorder`: the same path-traced image rendered once per reordering
// heuristic in one run, with each render's stage times, the simulated memory traffic of
// trace and approx_hit when [memory] asks for it, and whether the image equals the
// `none` image bit for bit (the reordering paper's Table III, on our scenes).
#pragma once

#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/memory/ray_spill.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/stages/reorder_keys.hpp"

namespace wavetrace {

// What one row renders: a reorder heuristic's wavefront render, or `paths`: no reordering and
// no wavefront, each path traced to its end before the next (pipeline.mode = megakernel), the
// paper's renderer without its reordering module ("process rays as they are generated").
struct ReorderBenchRow {
  ReorderBenchRow(ReorderHeuristic heuristic = ReorderHeuristic::none) : heuristic(heuristic) {}  // NOLINT: a heuristic is a row
  static ReorderBenchRow paths_row() {
    ReorderBenchRow row;
    row.paths = true;
    return row;
  }
  std::string name() const { return paths ? "paths" : to_string(heuristic); }

  ReorderHeuristic heuristic;
  bool paths = false;
};

// A row by its name: a heuristic's (reorder_keys.hpp) or "paths"; throws std::invalid_argument.
ReorderBenchRow parse_reorder_bench_row(const std::string& name);

struct ReorderBenchResult {
  std::string heuristic;
  double render_seconds = 0.0;  // the whole render: with photon mapping, both passes
  double photon_seconds = 0.0;  // photon mapping's photon pass and maps (within render_seconds)
  // The process's CPU over the render, every thread: a paged render's reads cost the kernel's
  // time (system) beside the walks' (user).
  double cpu_user_seconds = 0.0, cpu_system_seconds = 0.0;
  double trace_seconds = 0.0;       // thread-seconds in trace
  double trace_mrays_per_s = 0.0;   // per trace thread-second
  double closest_mrays_per_s = 0.0; // camera and bounce rays alone
  double shadow_mrays_per_s = 0.0;  // shadow rays alone
  double approx_hit_seconds = 0.0;
  double sort_seconds = 0.0;        // the zsort stage: keys, sort, gather
  double overhead_share = 0.0;      // (approx_hit + zsort) / all thread-seconds
  std::uint64_t rays_traced = 0;
  std::uint64_t rays_retired_by_approx_hit = 0;
  std::optional<std::uint64_t> page_faults;
  std::optional<std::uint64_t> bytes_loaded;
  std::optional<double> simulated_io_seconds;
  std::optional<std::uint64_t> cache_misses;
  // Real paging of a world file (memory.backing = file): pages read from disk, measured.
  std::optional<std::uint64_t> disk_faults;
  std::optional<std::uint64_t> disk_bytes_read;
  std::optional<double> disk_read_seconds;
  std::optional<double> disk_wait_seconds;          // trace's threads waiting for pages, summed
  std::optional<std::size_t> disk_reads_in_flight_max;
  std::optional<std::uint64_t> disk_prefetched;     // of disk_faults, pages trace's look-ahead read
  std::optional<std::uint64_t> disk_prefetch_hits;  // of those, pages trace read before they were evicted
  std::optional<double> disk_pages_per_1000_rays;   // distinct pages of 1,000 consecutive traced rays
  std::vector<std::pair<std::string, std::uint64_t>> disk_faults_by_part;
  std::optional<SpillCounters> spill;               // a disk ray buffer's runs
  std::optional<std::uint64_t> photon_disk_faults;  // of disk_faults, those of photon mapping's photon pass
  bool image_identical = false;  // to the first heuristic's image (none, when listed first)
};

struct ReorderBenchReport {
  std::string scene;
  std::size_t triangles = 0;
  std::string accel;
  std::string curve;
  std::string image;  // WxH, spp, depth
  int threads = 0;
  int rounds = 1;  // renders of each heuristic, interleaved; the one of median time is reported
  std::optional<std::string> proxy;  // method, triangles, quality
  std::string memory;                // pager and cache settings, or "off"
  std::uint64_t world_bytes = 0;     // the world file's size, when the scene is one
  std::size_t page_count = 0;        // the world's pages, when paged (real or simulated)
  std::vector<ReorderBenchResult> results;
};

// `config` holds every other setting (scene, accel, render, proxy, memory); each row gets
// reorder.heuristic and the chain it needs (`paths` the megakernel); `rounds` times over, the
// rows in turn. Throws ConfigError for a depth under 3 or no round.
ReorderBenchReport run_reorder_bench(const Config& config, const std::vector<ReorderBenchRow>& rows, int rounds = 1);

nlohmann::json to_json(const ReorderBenchReport& report);
std::string to_table(const ReorderBenchReport& report);

}  // namespace wavetrace
