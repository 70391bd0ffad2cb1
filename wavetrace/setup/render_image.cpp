// Plan and world to image.
#include "wavetrace/setup/render_image.hpp"

#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/pipeline/megakernel.hpp"
#include "wavetrace/stages/emit_photons.hpp"
#include "wavetrace/stages/photon_deposits.hpp"
#include "wavetrace/stages/shade.hpp"
#include "wavetrace/stages/spawn.hpp"
#include "wavetrace/setup/stage_chain.hpp"
#include "wavetrace/stages/trace.hpp"

namespace wavetrace {
namespace {

// A disk ray buffer writes at most a generation of rays: every path's bounce and shadow ray
// (two per camera sample), each its ray and key columns. Checked before
// anything is traced, so that a render never stops for want of disk halfway through.
void check_spill_space(const RenderPlan& plan) {
  if (plan.reorder.buffer != RayBufferKind::disk) return;
  const std::string directory =
      plan.reorder.spill_dir.empty() ? std::filesystem::temp_directory_path().string() : plan.reorder.spill_dir;
  const std::uint64_t free = spill_directory_free_bytes(directory);
  const std::uint64_t needed = 2 * std::uint64_t(plan.image.pixel_count()) * plan.image.samples_per_pixel *
                               (RayBatch::kBytesPerRay + RayBatch::kSortKeyBytesPerRay);
  if (needed > free) {
    throw SpillError(fmt::format("reorder.spill_dir = {}: a generation of this render's rays may need {:.2f} GB on "
                                 "disk and {:.2f} GB are free",
                                 directory, double(needed) * 1e-9, double(free) * 1e-9));
  }
}

// Photon mapping's first pass: photons from the lights through the plan's chain (reordered
// as camera rays are), left on diffuse surfaces, then the two maps built from them.
// A photon count whose maps cannot fit is refused before anything is traced, rather than
// killed for memory halfway through the photon pass. A photon lands about 3 times in a closed
// room (room:1M 2.8, the glass room 2.8), and a landing holds about 128 bytes at the peak,
// while the deposits are merged (two 48-byte copies) and the maps built (36 bytes, the trees).
void check_photon_memory(const RenderPlan& plan) {
  constexpr double kLandingsPerPhoton = 3.0, kBytesPerLanding = 128.0;
  const double needed = double(plan.photon.count) * kLandingsPerPhoton * kBytesPerLanding;
  const std::size_t available = available_memory_bytes();
  if (available > 0 && needed > double(available)) {
    throw ConfigError(fmt::format("photon.count = {}: its photon maps would need about {:.1f} GB ({} bytes a photon) "
                                  "and {:.1f} GB are available",
                                  plan.photon.count, needed * 1e-9, kLandingsPerPhoton * kBytesPerLanding,
                                  double(available) * 1e-9));
  }
}

// photon.radius = 0: this share of the scene's diagonal.
constexpr float kAutoRadiusShare = 0.0025f;

// [memory]'s observers see both passes: their counts, reported with the camera pass's
// stages, are the whole render's.
std::unique_ptr<PhotonMaps> run_photon_pass(const RenderPlan& plan, const World& world, const MemoryObservers* observers,
                                            const std::function<void(const Progress&)>& on_progress,
                                            BatchPool& batches, PhotonPassReport& report) {
  check_photon_memory(plan);
  PhotonDeposits deposits;
  EmitPhotonsStage emit(world.lights, plan.photon.count, plan.image.seed);
  const StageChain chain(plan, world, nullptr, observers, ChainShading{.deposits = &deposits});
  Pipeline pipeline(emit, chain.stages(), chain.loops(), plan.pipeline, &batches);
  report.run = pipeline.run(on_progress);
  report.emitted = emit.generated();
  // The observation emptied the pager before this pass: all it has read is the photons'.
  if (observers != nullptr && plan.memory.file_backing && world.pager != nullptr) report.disk = world.pager->total();
  const auto start = std::chrono::steady_clock::now();
  PhotonDeposits::Maps landed = deposits.take();
  report.global_photons = landed.global.size();
  report.caustic_photons = landed.caustic.size();
  // A wider reach blurs caustics (on scenes/caustic.toml, 1% of the diagonal put 15% more light
  // around the ball than the path tracer finds, 0.25% under 7%: docs/photon-mapping.md).
  report.radius = plan.photon.radius > 0.0f ? plan.photon.radius
                                            : kAutoRadiusShare * glm::length(world.scene.bounds.upper - world.scene.bounds.lower);
  auto maps = std::make_unique<PhotonMaps>(std::move(landed.global), std::move(landed.caustic), plan.photon.k,
                                           report.radius, plan.photon.precompute);
  report.precomputed = maps->global.precomputed_count();
  report.map_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return maps;
}

}  // namespace

RenderOutput render_image(const RenderPlan& plan, const World& world, const Camera& camera,
                          const std::function<void(const Progress&)>& on_progress, const ImageShare& share) {
  check_spill_space(plan);
  if (share.camera_rays && plan.pipeline.mode == PipelineMode::megakernel) {
    throw ConfigError("pipeline.mode = megakernel walks the image's pixels itself: a shared image (a distributed "
                      "render) needs the wavefront pipeline");
  }
  const int workers = worker_count(plan.pipeline);
  Film film(plan.image.width, plan.image.height, plan.film_per_thread ? std::uint32_t(workers) : 0);
  GenerateStage generate(camera, plan.image, plan.pixel_order, share.camera_rays);
  std::optional<MemoryObservation> observation;
  RenderOutput output;
  if (plan.memory.enabled()) {
    if (world.accelerator.probed()) {
      std::vector<std::span<const std::byte>> spans = world.accelerator.memory_spans();
      if (world.proxy != nullptr && plan.needs_proxy()) {
        for (const auto& span : world.proxy->accelerator().memory_spans()) spans.push_back(span);
      }
      observation.emplace(plan.memory, std::move(spans), workers, plan.memory.file_backing ? world.pager : nullptr,
                          world.accelerator.reads_through_frames());
    } else {
      output.memory_unobserved = fmt::format("accelerator '{}' cannot report its memory reads: no pager or cache counters",
                                             world.accelerator.name());
    }
  }
  if (plan.pipeline.mode == PipelineMode::megakernel) {
    // The control experiment runs without the trace stage's per-run clocks and counters,
    // but for [memory]'s: observed, its walks page a world file as the wavefront's do.
    const TraceStage trace(world.accelerator, world.scene.material_runs,
                           TraceInstruments{.observers = observation ? &observation->observers() : nullptr});
    const ShadeStage shade(world, film, plan.rules);
    const SpawnStage spawn(world, plan.rules);
    output.run = run_megakernel(generate, trace, shade, &spawn, {plan.pipeline.threads, plan.pipeline.tile_side},
                                on_progress);
    if (observation) observation->report(output.run.stages);
  } else {
    std::unique_ptr<PhotonMaps> maps;
    BatchPool batches(plan.pipeline.batch_size);  // both passes' batches: the camera pass reuses the photons'
    if (plan.integrator == Integrator::photon) {
      output.photons.emplace();
      maps = run_photon_pass(plan, world, observation ? &observation->observers() : nullptr, on_progress, batches,
                             *output.photons);
    }
    const StageChain chain(plan, world, &film, observation ? &observation->observers() : nullptr,
                           ChainShading{.maps = maps.get()});
    Pipeline pipeline(generate, chain.stages(), chain.loops(), plan.pipeline, &batches);
    output.run = pipeline.run(on_progress);
    if (observation) observation->report(output.run.stages);
    if (chain.zsort() != nullptr) {
      output.sort_seconds = chain.zsort()->sort_seconds();
      if (plan.reorder.buffer == RayBufferKind::disk) {
        for (StageStats& stage : output.run.stages) {
          if (stage.name == chain.zsort()->name()) stage.spill = chain.zsort()->spill();
        }
      }
    }
    output.closest_mrays_per_s = chain.trace_times().closest_mrays_per_s();
    output.any_mrays_per_s = chain.trace_times().any_mrays_per_s();
    output.hit_rates = chain.hit_rates().snapshot();
  }
  if (share.combine_film) {
    std::vector<std::int64_t> sums = film.sums();
    share.combine_film(sums);
    output.image = Film::resolve(sums, plan.image.samples_per_pixel);
  } else {
    output.image = film.resolve(plan.image.samples_per_pixel);
  }
  output.rejected_contributions = film.rejected_contributions();
  return output;
}

}  // namespace wavetrace
