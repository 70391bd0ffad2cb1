// `wavetrace bench sort`: zsort's flush timed apart from any render. A buffer of rays scattered
// over a box (origins, directions and approximate hits drawn uniformly: the order a sort must
// undo completely) is flushed once per heuristic and curve: nanoseconds a ray for the keys,
// the sort of (key, batch, ray) entries, and the gather of the rays into batches in key order.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/stages/reorder_keys.hpp"

namespace wavetrace {

struct SortBenchRequest {
  std::vector<ReorderHeuristic> heuristics;
  std::vector<CurveKind> curves;
  std::size_t rays = 262144;      // the buffer: reorder.buffer_rays' default
  std::size_t batch_size = 1024;  // rays a batch, in and out (render.batch_size's default)
  int threads = 1;                // the flush's parallel loops run on this many
  int repeats = 5;                // flushes per row; the median's phases are reported
};

struct SortBenchResult {
  ReorderHeuristic heuristic = ReorderHeuristic::none;
  CurveKind curve = CurveKind::morton;
  // Of the flush of median time (thread-seconds are not summed: wall time on `threads`).
  double flush_ns = 0.0;   // the whole flush, a ray
  double keys_ns = 0.0;    // compute_sort_keys over the held batches, a batch a task, timed on its own
  double sort_ns = 0.0;    // the sort of the entries (ZSortStage::sort_seconds)
  double gather_ns = 0.0;  // the rest: entries, the gather into batches in key order, hand-off
};

struct SortBenchReport {
  std::size_t rays = 0, batch_size = 0;
  int threads = 0, repeats = 0;
  std::vector<SortBenchResult> results;
};

// Throws ConfigError for an empty request, no rays or a batch size of 0.
SortBenchReport run_sort_bench(const SortBenchRequest& request);

nlohmann::json to_json(const SortBenchReport& report);
std::string to_table(const SortBenchReport& report);

}  // namespace wavetrace
