// A shared render: a barrier, each rank's render through the dealer (and in data mode its
// exchange, answering the others until all are done), a sum of the films to rank 0, and each
// rank's report gathered there.
#include "wavetrace/distribute/shared_render.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include "wavetrace/distribute/ray_range_dealer.hpp"
#include "wavetrace/memory/process_memory.hpp"

#if WAVETRACE_HAVE_MPI
#include <mpi.h>
#endif

namespace wavetrace {
namespace {

using Clock = std::chrono::steady_clock;

// A RankReport as it travels: fixed size, so that MPI_Gather moves plain bytes.
struct PackedRankReport {
  std::int32_t rank;
  char host[64];
  std::uint64_t ranges, camera_rays, rays_traced;
  double render_seconds, wait_seconds;
  double cpu_user_seconds, cpu_system_seconds;
  std::uint64_t peak_resident_bytes, load_peak_resident_bytes;
  ChunkTraffic traffic;  // plain numbers
};

PackedRankReport pack(const RankReport& report) {
  PackedRankReport packed{};
  packed.rank = report.rank;
  std::strncpy(packed.host, report.host.c_str(), sizeof packed.host - 1);
  packed.ranges = report.ranges;
  packed.camera_rays = report.camera_rays;
  packed.rays_traced = report.rays_traced;
  packed.render_seconds = report.render_seconds;
  packed.wait_seconds = report.wait_seconds;
  packed.cpu_user_seconds = report.cpu.user_seconds;
  packed.cpu_system_seconds = report.cpu.system_seconds;
  packed.peak_resident_bytes = report.peak_resident_bytes;
  packed.load_peak_resident_bytes = report.load_peak_resident_bytes;
  packed.traffic = report.traffic;
  return packed;
}

RankReport unpack(const PackedRankReport& packed) {
  RankReport report;
  report.rank = packed.rank;
  report.host = std::string(packed.host, strnlen(packed.host, sizeof packed.host));
  report.ranges = packed.ranges;
  report.camera_rays = packed.camera_rays;
  report.rays_traced = packed.rays_traced;
  report.render_seconds = packed.render_seconds;
  report.cpu = {packed.cpu_user_seconds, packed.cpu_system_seconds};
  report.wait_seconds = packed.wait_seconds;
  report.peak_resident_bytes = packed.peak_resident_bytes;
  report.load_peak_resident_bytes = packed.load_peak_resident_bytes;
  report.traffic = packed.traffic;
  return report;
}

const StageStats* find_stage(const PipelineRun& run, const std::string& name) {
  const auto found = std::find_if(run.stages.begin(), run.stages.end(), [&](const StageStats& s) { return s.name == name; });
  return found == run.stages.end() ? nullptr : &*found;
}

// What must be the same on every rank for their films to add up to one image.
std::uint64_t render_fingerprint(const RenderPlan& plan, const World& world) {
  // The structure's bytes tell its chunking and settings apart too.
  const std::string facts =
      fmt::format("{} {} {} {} {}x{} {} spp seed {} depth {} roulette {} {} {} {}", world.scene.name,
                  world.scene.triangle_count, world.accelerator.name(), world.accelerator.memory().total(),
                  plan.image.width, plan.image.height, plan.image.samples_per_pixel, plan.image.seed,
                  plan.rules.max_depth, plan.rules.russian_roulette_depth, to_string(plan.reorder.heuristic),
                  to_string(plan.distribute.mode), plan.stages.size());
  return std::hash<std::string>{}(facts);
}

}  // namespace

std::uint64_t DistributedRender::rays_traced() const {
  std::uint64_t total = 0;
  for (const RankReport& rank : ranks) total += rank.rays_traced;
  return total;
}

std::uint64_t range_rays_for(const RenderPlan& plan, int ranks) {
  if (plan.distribute.range_rays > 0) return plan.distribute.range_rays;
  const std::uint64_t total = std::uint64_t(plan.image.pixel_count()) * plan.image.samples_per_pixel;
  return std::max<std::uint64_t>(16 * plan.pipeline.batch_size, total / (64 * std::uint64_t(std::max(ranks, 1))));
}

DistributedRender render_shared(const MpiSession& session, const RenderPlan& plan, const World& world,
                                const Camera& camera, const std::function<void(const Progress&)>& on_progress,
                                const RankSetup& setup) {
  ChunkExchange* const exchange = setup.exchange;
#if !WAVETRACE_HAVE_MPI
  if (session.distributed()) throw std::logic_error("a distributed session in a build without MPI");
#endif
  DistributedRender result;
  result.range_rays = range_rays_for(plan, session.ranks());
  const std::uint64_t total = std::uint64_t(plan.image.pixel_count()) * plan.image.samples_per_pixel;
#if WAVETRACE_HAVE_MPI
  // Every rank has its world before the clock starts (the measured time is the render's), and
  // all hold the same one: ranks started with different arguments would sum unrelated films.
  if (session.distributed()) {
    const std::uint64_t own = render_fingerprint(plan, world);
    std::uint64_t least[2] = {own, ~own};  // the least of ~x is ~(the most of x)
    MPI_Allreduce(MPI_IN_PLACE, least, 2, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
    if (least[0] != ~least[1]) {
      throw std::runtime_error("the ranks do not render the same world and image (the scene, its structure or the "
                               "image settings differ between them): start every rank with the same arguments");
    }
  }
#endif
  const Clock::time_point start = Clock::now();
  const ProcessCpuTime cpu_at_start = read_process_cpu_time();
  RayRangeDealer dealer(session, total, result.range_rays);
  RankReport own;
  ImageShare share;
  share.camera_rays = [&dealer] { return dealer.next(); };
  share.combine_film = [&](std::vector<std::int64_t>& sums) {
    own.render_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    // The others may still need this rank's chunks: answer them until all are done (only then
    // wait for the dealer, whose last answers go to ranks finishing their renders).
    if (exchange != nullptr) exchange->finish();
    dealer.finish();
    own.cpu = read_process_cpu_time() - cpu_at_start;
#if WAVETRACE_HAVE_MPI
    if (!session.distributed()) return;
    const auto count = static_cast<int>(sums.size());
    if (session.rank() == 0) {
      MPI_Reduce(MPI_IN_PLACE, sums.data(), count, MPI_INT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    } else {
      MPI_Reduce(sums.data(), nullptr, count, MPI_INT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
      sums.clear();  // only rank 0 holds the image
    }
#endif
  };
  result.output = render_image(plan, world, camera, on_progress, share);
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();

  own.rank = session.rank();
  own.host = session.host();
  own.ranges = dealer.ranges_taken();
  const StageStats* generate = find_stage(result.output.run, "generate");
  const StageStats* trace = find_stage(result.output.run, "trace");
  own.camera_rays = generate != nullptr ? generate->rays_out : 0;
  own.rays_traced = trace != nullptr ? trace->rays_in : 0;
  own.wait_seconds = dealer.wait_seconds();
  own.peak_resident_bytes = read_resident_memory().peak_bytes;
  own.load_peak_resident_bytes = setup.load_peak_resident_bytes;
  if (exchange != nullptr) own.traffic = exchange->traffic();
  if (!session.distributed()) {
    result.ranks = {own};
    return result;
  }
#if WAVETRACE_HAVE_MPI
  const PackedRankReport packed = pack(own);
  std::vector<PackedRankReport> all(session.rank() == 0 ? std::size_t(session.ranks()) : 0);
  MPI_Gather(&packed, sizeof packed, MPI_BYTE, all.data(), sizeof packed, MPI_BYTE, 0, MPI_COMM_WORLD);
  for (const PackedRankReport& report : all) result.ranks.push_back(unpack(report));
#endif
  return result;
}

}  // namespace wavetrace
