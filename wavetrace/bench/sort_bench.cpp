// zsort's flush of a scattered buffer, phase by phase, on a fixed number of threads.
#include "wavetrace/bench/sort_bench.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/memory/batch_pool.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/stages/zsort.hpp"

namespace wavetrace {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kMostRays = std::size_t{1} << 26, kMostBatchRays = std::size_t{1} << 20;

// The flushed batches go back to the pool at once: the next flush reuses them, as a render's does.
class ReturningOutput final : public StageOutput {
 public:
  explicit ReturningOutput(BatchPool& pool) : pool_(pool) {}
  void emit(Batch* batch) override { pool_.release(batch); }
  Batch* acquire() override { return pool_.acquire(); }
  void release(Batch* batch) override { pool_.release(batch); }

 private:
  BatchPool& pool_;
};

// `rays` bounce rays over [-1, 1]^3 in batches of the pool's size, every column a render's
// ray has written; `round` draws another set.
std::vector<Batch*> scattered_rays(BatchPool& pool, std::size_t rays, std::uint32_t round) {
  std::vector<Batch*> batches;
  for (std::size_t r = 0; r < rays; ++r) {
    if (r % pool.batch_capacity() == 0) batches.push_back(pool.acquire());
    RayBatch& batch = batches.back()->rays;
    batch.enable_approx_hit();
    const std::size_t i = batch.count++;
    const auto pixel = static_cast<std::uint32_t>(r);
    const UnitPair a = unit_pair(random_bits(pixel, round, 0, RandomPurpose::benchmark));
    const UnitPair b = unit_pair(random_bits(pixel, round, 1, RandomPurpose::benchmark));
    const UnitPair c = unit_pair(random_bits(pixel, round, 2, RandomPurpose::benchmark));
    const glm::vec3 direction = glm::normalize(glm::vec3(b.second - 0.5f, c.first - 0.5f, a.second - 0.45f));
    batch.set_geometry(i, glm::vec3(a.first, a.second, b.first) * 2.0f - 1.0f, direction, 1e-4f, 10.0f);
    batch.approx_hit_x[i] = c.second * 2.0f - 1.0f;
    batch.approx_hit_y[i] = a.first * 2.0f - 1.0f;
    batch.approx_hit_z[i] = b.second * 2.0f - 1.0f;
    batch.pixel[i] = pixel;
    batch.sample[i] = round;
    batch.depth[i] = 1;
    batch.kind[i] = RayKind::bounce;
    batch.throughput_r[i] = batch.throughput_g[i] = batch.throughput_b[i] = 0.5f;
    batch.flags[i] = ray_flags::alive;
  }
  return batches;
}

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

SortBenchResult time_flushes(const SortBenchRequest& request, ReorderHeuristic heuristic, CurveKind curve) {
  const Bounds3 box{glm::vec3(-1.0f), glm::vec3(1.0f)};
  BatchPool pool(request.batch_size);
  ZSortOptions options;
  options.heuristic = heuristic;
  options.curve = curve;
  options.buffer_rays = request.rays + 1;  // held until the flush
  const ZSortStage zsort(options, box);
  ReturningOutput out(pool);
  std::vector<SortBenchResult> flushes;
  // One flush more than asked, not counted: the first touches the pool's and the entries' memory.
  for (int round = 0; round <= request.repeats; ++round) {
    const std::vector<Batch*> batches = scattered_rays(pool, request.rays, std::uint32_t(round));
    SortBenchResult flush{heuristic, curve};
    const double ns_a_ray = 1e9 / double(request.rays);
    if (heuristic != ReorderHeuristic::none) {
      // As the flush makes them: a batch a task.
      const Clock::time_point start = Clock::now();
      tbb::parallel_for(std::size_t{0}, batches.size(),
                        [&](std::size_t b) { compute_sort_keys(batches[b]->rays, heuristic, curve, box); });
      flush.keys_ns = seconds_since(start) * ns_a_ray;
    }
    for (Batch* batch : batches) zsort.buffer(batch);
    const double sorted_before = zsort.sort_seconds();
    const Clock::time_point start = Clock::now();
    zsort.flush(out);
    flush.flush_ns = seconds_since(start) * ns_a_ray;
    flush.sort_ns = (zsort.sort_seconds() - sorted_before) * ns_a_ray;
    flush.gather_ns = std::max(0.0, flush.flush_ns - flush.sort_ns - flush.keys_ns);
    if (round > 0) flushes.push_back(flush);
  }
  std::sort(flushes.begin(), flushes.end(),
            [](const SortBenchResult& a, const SortBenchResult& b) { return a.flush_ns < b.flush_ns; });
  return flushes[flushes.size() / 2];
}

}  // namespace

SortBenchReport run_sort_bench(const SortBenchRequest& request) {
  if (request.heuristics.empty() || request.curves.empty()) throw ConfigError("bench sort: no heuristic or no curve");
  // Bounds that keep the buffer (about 140 bytes a ray with its hits and entries) and a batch
  // within this kind of machine, as render.batch_size's range does.
  if (request.rays < 1 || request.rays > kMostRays) {
    throw ConfigError(fmt::format("bench sort: --rays {} is out of range [1, {}]", request.rays, kMostRays));
  }
  if (request.batch_size < 16 || request.batch_size > kMostBatchRays) {
    throw ConfigError(
        fmt::format("bench sort: --batch-size {} is out of range [16, {}]", request.batch_size, kMostBatchRays));
  }
  if (request.repeats < 1) throw ConfigError("--repeat must be at least 1");
  if (request.threads < 1) throw ConfigError("bench sort: --threads must be at least 1");
  SortBenchReport report{request.rays, request.batch_size, request.threads, request.repeats, {}};
  tbb::task_arena arena(request.threads);
  arena.execute([&] {
    for (const CurveKind curve : request.curves) {
      for (const ReorderHeuristic heuristic : request.heuristics) {
        report.results.push_back(time_flushes(request, heuristic, curve));
      }
    }
  });
  return report;
}

nlohmann::json to_json(const SortBenchReport& report) {
  nlohmann::json results = nlohmann::json::array();
  for (const SortBenchResult& r : report.results) {
    results.push_back({{"heuristic", to_string(r.heuristic)},
                       {"curve", to_string(r.curve)},
                       {"flush_ns_per_ray", r.flush_ns},
                       {"keys_ns_per_ray", r.keys_ns},
                       {"sort_ns_per_ray", r.sort_ns},
                       {"gather_ns_per_ray", r.gather_ns}});
  }
  return {{"rays", report.rays},
          {"batch_size", report.batch_size},
          {"threads", report.threads},
          {"repeats", report.repeats},
          {"results", results}};
}

std::string to_table(const SortBenchReport& report) {
  std::string table = fmt::format(
      "zsort's flush of {} scattered rays in batches of {}, {} thread(s), the median of {} flushes (ns a ray)\n",
      report.rays, report.batch_size, report.threads, report.repeats);
  table += fmt::format("{:<12} {:<8} {:>9} {:>9} {:>9} {:>9}\n", "heuristic", "curve", "flush", "keys", "sort", "gather");
  for (const SortBenchResult& r : report.results) {
    table += fmt::format("{:<12} {:<8} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f}\n", to_string(r.heuristic),
                         to_string(r.curve), r.flush_ns, r.keys_ns, r.sort_ns, r.gather_ns);
  }
  table += "keys: the flush's loop making them, timed on its own; gather: the flush less the sort and the keys\n";
  return table;
}

}  // namespace wavetrace
