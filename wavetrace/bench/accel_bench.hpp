// `wavetrace bench accel`: every accelerator built and timed on the same rays in one run,
// with its accuracy measured against Embree on those rays.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/scene.hpp"
#include "wavetrace/setup/accel_choice.hpp"
#include "wavetrace/setup/accelerator_spec.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/pipeline/memory_observation.hpp"

namespace wavetrace {

// "TYPE[:key=value]..." where each key is accel.TYPE.key, e.g. "bvh:layout=veb:leaf_size=8",
// "embree:mode=robust"; "auto[:memory_budget=..][:max_error=..]" sets accel.type = auto and
// its accel.* keys; other keys come from `base`. Throws ConfigError naming bad parts.
struct AcceleratorSpec {
  std::string label;
  AcceleratorOptions options;
  AccelGoal goal;  // auto or a pixel epsilon: resolved on the scene by resolve_accelerator_spec
  std::optional<AccelChoice> auto_choice;  // once resolved: what auto chose and why
};
AcceleratorSpec parse_accelerator_spec(const std::string& text, const Config& base);
// Resolves auto or hmq:epsilon=pixel against `scene`, its camera (or camera.* of `base`) and
// render.width x render.height of `base`; the label then names what it came to, as
// "auto (hmq:width=8:epsilon=0.00123)". Other specs are left as they are.
void resolve_accelerator_spec(AcceleratorSpec& spec, const Scene& scene, const Config& base);

// One probed pass of the ray set: the pager at one budget and/or the simulated cache, and
// the trace speed with the probes on (the uninstrumented speed is the result's own).
struct MemoryRun {
  std::string budget;          // as given ("20%"), empty without a pager
  std::size_t world_bytes = 0;
  std::optional<PagerStats> pager;
  std::optional<CacheStats> cache;
  double instrumented_mrays_per_s = 0.0;
};

// How far beyond a lossy accelerator's vertex error its agreement is measured again: a ray
// leaving a surface offset by e meets it within e / cos(angle) of its start, and under 0.4% of
// cosine-distributed directions lie within cos = 1/16 of the surface.
inline constexpr double kBeyondErrorFactor = 16.0;

struct AccelBenchResult {
  std::string label;
  MemoryReport memory;
  double bytes_per_triangle = 0.0;
  BuildReport build;  // its peak_bytes: the build's own accounting (Embree's: its allocation monitor)
  // The build's peak resident memory read from the OS (VmHWM, reset before the build) above
  // what the process held when it began; 0 where the peak cannot be reset.
  std::size_t build_peak_rss_above_start_bytes = 0;
  std::string build_notes;
  std::string isa;  // the instruction set its walks ran (Accelerator::isa)
  std::vector<double> mrays_per_s_runs;
  double mrays_per_s = 0.0;      // median of the runs
  // Its speed against the first result's: interleaved, the median of the rounds' ratios
  // (vs_first_runs, run k against the first's run k); one at a time, the ratio of the medians.
  double vs_first = 0.0;
  std::vector<double> vs_first_runs;
  double hit_agreement = 0.0;    // same hit / miss as the reference
  std::optional<double> prim_agreement;  // same primitive where both hit (closest-hit sets only)
  std::optional<double> t_error_max;     // |t - t_ref| / scene diagonal where both hit
  std::optional<double> t_error_mean;
  // Lossy accelerators (Accelerator::represented_mesh): how far its hit points lie from the
  // mesh's own triangle at the same barycentrics, and the bound it promises (the largest
  // distance any vertex moved). Closest-hit sets only.
  std::optional<double> surface_error_max;
  std::optional<double> vertex_error_max;
  // Lossy accelerators, rays that start on a surface (diffuse, shadow): the same rays started
  // beyond kBeyondErrorFactor times the vertex error, traced by it and by the reference, so a
  // ray no longer meets the lossy surface it starts on. What is left to disagree are cracks
  // and real differences of shape; `self_hits` is the share of rays that found a hit of the
  // accelerator's own within that start and none of the reference's.
  std::optional<double> beyond_error_start;
  std::optional<double> beyond_error_hit_agreement;
  std::optional<double> beyond_error_prim_agreement;
  std::optional<double> self_hits;
  bool probed = false;                 // false: the accelerator's reads cannot be observed (Embree)
  std::vector<MemoryRun> memory_runs;  // one per budget, when memory observation was asked for
  // With --reads: the probe's reads of one pass, by world array (memory_spans order; the last
  // entry counts reads outside them), and each array's bytes.
  std::vector<std::uint64_t> reads_by_array;
  std::vector<std::size_t> array_bytes;
  std::optional<AccelChoice> auto_choice;  // the spec was auto: its candidates and reasons
};

struct AccelBenchReport {
  std::string scene;
  std::size_t triangles = 0;
  std::string reference;
  std::string rays;
  std::size_t ray_count = 0;
  int threads = 0;
  int repeats = 0;
  // The runs were timed in rounds, each accelerator once a round in turn, all of them built
  // first; else each accelerator was built, timed and dropped before the next.
  bool interleaved = false;
  bool packets = false;
  double reference_hit_rate = 0.0;  // share of rays Embree finds a hit (occluded, for shadow rays)
  bool memory_observed = false;     // memory runs were asked for
  std::vector<AccelBenchResult> results;
};

struct AccelBenchRequest {
  std::vector<AcceleratorSpec> accelerators;
  AcceleratorSpec reference{"embree", AcceleratorOptions{}, AccelGoal{}, std::nullopt};  // accuracy is measured against it
  RaySetKind rays = RaySetKind::primary;
  std::size_t count = 1 << 20;
  int threads = 0;
  int repeats = 3;
  // Time each accelerator's runs back to back and drop it before building the next, where
  // holding all of them at once would not fit (a 64M room's Embree and BVHs): the ratios
  // then compare runs minutes apart on a machine whose speed drifts.
  bool one_at_a_time = false;
  bool packets = false;  // primary rays through intersect_coherent (packets where an accelerator has them)
  // The simulated pager's settings and cache; `budgets` (e.g. "100%", "20%") replace memory.budget when given.
  MemoryPlan memory;
  std::vector<std::string> budgets;
  bool count_reads = false;  // one probed pass counting reads per world array (nodes, leaves, ...)
  // A saved world (bench accel --scene FILE.wtw): measured instead of `accelerators`, with
  // its load in place of a build; the reference is built from its geometry when it has some,
  // else the world answers for itself (accuracy then compares it with itself).
  const Accelerator* world = nullptr;
  const LightSampler* world_lights = nullptr;
  std::string world_label;
  double world_load_seconds = 0.0;
};

AccelBenchReport run_accel_bench(const Scene& scene, const AccelBenchRequest& request);

nlohmann::json to_json(const AccelBenchReport& report);
std::string to_csv(const AccelBenchReport& report);
std::string to_table(const AccelBenchReport& report);

}  // namespace wavetrace
