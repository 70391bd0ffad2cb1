// One path at a time through trace, shade and spawn, each called on a one-ray batch.
#include "wavetrace/pipeline/megakernel.hpp"

#include <atomic>
#include <optional>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "wavetrace/memory/memory_probe.hpp"
#include "wavetrace/pipeline/tracing_arena.hpp"
#include "wavetrace/stages/observed_stage.hpp"

namespace wavetrace {
namespace {

using Clock = std::chrono::steady_clock;

// A worker's rays: the path's current ray, the next bounce and a shadow ray, one slot each.
struct PathScratch {
  Batch current{1}, next{1}, shadow{1};
  std::uint64_t rays_traced = 0;
  std::uint64_t nanoseconds = 0;
  std::uint64_t trace_nanoseconds = 0;  // observed runs only
};

}  // namespace

PipelineRun run_megakernel(const GenerateStage& generate, const TraceStage& trace, const ShadeStage& shade,
                           const SpawnStage* spawn, const MegakernelOptions& options,
                           const std::function<void(const Progress&)>& on_progress,
                           std::chrono::milliseconds interval) {
  TracingArena arena(options.threads);
  const ImageSpec& image = generate.image();
  const std::uint32_t side = std::max<std::uint32_t>(options.tile_side, 1);
  const std::uint32_t tiles_x = (image.width + side - 1) / side, tiles_y = (image.height + side - 1) / side;
  const std::uint64_t total = std::uint64_t(image.pixel_count()) * image.samples_per_pixel;
  const RayRange one{0, 1};

  tbb::enumerable_thread_specific<PathScratch> scratch;
  std::atomic<std::uint64_t> camera_rays_done{0}, rays_traced{0};  // for progress reports
  const Clock::time_point start = Clock::now();
  const ProcessCpuTime cpu_at_start = read_process_cpu_time();
  std::optional<ProgressReporter> reporter;
  reporter.emplace(
      on_progress,
      [&] {
        const std::uint64_t done = camera_rays_done.load(std::memory_order_relaxed);
        return Progress{done, total, rays_traced.load(std::memory_order_relaxed),
                        std::chrono::duration<double>(Clock::now() - start).count()};
      },
      interval);

  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, tiles_x * tiles_y, 1), [&](const auto& tiles) {
      const Clock::time_point busy_since = Clock::now();
      PathScratch& s = scratch.local();
      const std::uint64_t traced_before = s.rays_traced;
      std::uint64_t paths = 0;
      // Observed ([memory]), each ray's walk goes through the trace stage's probe, which pages
      // a world read from a file, and is timed apart as the wavefront's trace stage is.
      // Windows of a worker's consecutive rays, whatever their kind, count the distinct pages
      // they touch as the wavefront's runs do (a window's tail at the end is dropped).
      std::optional<RecordingProbe> probe;
      std::uint32_t window_rays = 0;
      if (const MemoryObservers* observers = trace.observers()) {
        probe.emplace(*observers, std::size_t(ObservedStage::trace),
                      std::size_t(tbb::this_task_arena::current_thread_index()));
        probe->count_ray_windows();
      }
      const auto trace_one = [&](Batch& batch) {
        ++s.rays_traced;
        if (!probe) return trace.trace_one_ray(batch, nullptr);
        const Clock::time_point since = Clock::now();
        trace.trace_one_ray(batch, &*probe);
        if (++window_rays == TraceStage::kRayWindow) {
          probe->end_ray_window(true);
          window_rays = 0;
        }
        s.trace_nanoseconds += static_cast<std::uint64_t>(
            std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - since).count());
      };
      for (std::uint32_t tile = tiles.begin(); tile != tiles.end(); ++tile) {
        const std::uint32_t x0 = tile % tiles_x * side, y0 = tile / tiles_x * side;
        for (std::uint32_t y = y0; y < std::min(y0 + side, image.height); ++y) {
          for (std::uint32_t x = x0; x < std::min(x0 + side, image.width); ++x) {
            for (std::uint32_t sample = 0; sample < image.samples_per_pixel; ++sample) {
              Batch* current = &s.current;
              Batch* next = &s.next;
              generate.write_camera_ray(current->rays, 0, y * image.width + x, sample);
              current->rays.count = 1;
              for (;;) {
                trace_one(*current);
                if (shade.shade(*current, one) == 0 || spawn == nullptr) break;
                next->rays.count = 0;
                s.shadow.rays.count = 0;
                spawn->spawn(*current, one, next->rays, &s.shadow.rays);
                if (s.shadow.rays.count > 0) {
                  trace_one(s.shadow);
                  shade.shade(s.shadow, one);
                }
                if (next->rays.count == 0) break;
                std::swap(current, next);
              }
              ++paths;
            }
          }
        }
      }
      camera_rays_done.fetch_add(paths, std::memory_order_relaxed);
      rays_traced.fetch_add(s.rays_traced - traced_before, std::memory_order_relaxed);
      s.nanoseconds += static_cast<std::uint64_t>(
          std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - busy_since).count());
    });
  });

  PipelineRun run;
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  run.cpu = read_process_cpu_time() - cpu_at_start;
  reporter.reset();
  run.threads = arena.threads();
  StageStats stats;
  stats.name = "megakernel";
  for (const PathScratch& s : scratch) {
    stats.rays_in += s.rays_traced;
    stats.seconds += double(s.nanoseconds) * 1e-9;
  }
  stats.rays_out = 0;
  run.stages.push_back(stats);
  if (trace.observers() != nullptr) {
    // The walks alone, under the wavefront's name for them, where [memory] reports its counts.
    StageStats walks;
    walks.name = trace.name();
    walks.rays_in = walks.rays_out = stats.rays_in;
    for (const PathScratch& s : scratch) walks.seconds += double(s.trace_nanoseconds) * 1e-9;
    run.stages.push_back(walks);
  }
  return run;
}

}  // namespace wavetrace
