// Plan and world to image.
#include "wavetrace/setup/render_image.hpp"

#include <fmt/format.h>

#include "wavetrace/pipeline/megakernel.hpp"
#include "wavetrace/stages/shade.hpp"
#include "wavetrace/stages/spawn.hpp"
#include "wavetrace/setup/stage_chain.hpp"
#include "wavetrace/stages/trace.hpp"

namespace wavetrace {

RenderOutput render_image(const RenderPlan& plan, const World& world, const Camera& camera,
                          const std::function<void(const Progress&)>& on_progress) {
  const int workers = worker_count(plan.pipeline);
  Film film(plan.image.width, plan.image.height, plan.film_per_thread ? std::uint32_t(workers) : 0);
  GenerateStage generate(camera, plan.image, plan.pixel_order);
  std::optional<MemoryObservation> observation;
  RenderOutput output;
  if (plan.memory.enabled()) {
    if (world.accelerator.probed()) {
      std::vector<std::span<const std::byte>> spans = world.accelerator.memory_spans();
      if (world.proxy != nullptr && plan.needs_proxy()) {
        for (const auto& span : world.proxy->accelerator().memory_spans()) spans.push_back(span);
      }
      observation.emplace(plan.memory, std::move(spans), workers, plan.memory.file_backing ? world.pager : nullptr);
    } else {
      output.memory_unobserved = fmt::format("accelerator '{}' cannot report its memory reads: no pager or cache counters",
                                             world.accelerator.name());
    }
  }
  if (plan.pipeline.mode == PipelineMode::megakernel) {
    // The control experiment runs without the trace stage's per-run clocks and counters
    // (and plan_render refused [memory] observation for it).
    const TraceStage trace(world.accelerator, world.scene.material_runs);
    const ShadeStage shade(world, film, plan.rules);
    const SpawnStage spawn(world, plan.rules);
    output.run = run_megakernel(generate, trace, shade, &spawn, {plan.pipeline.threads, plan.pipeline.tile_side},
                                on_progress);
  } else {
    const StageChain chain(plan, world, film, observation ? &observation->observers() : nullptr);
    Pipeline pipeline(generate, chain.stages(), chain.loops(), plan.pipeline);
    output.run = pipeline.run(on_progress);
    if (observation) observation->report(output.run.stages);
    if (chain.zsort() != nullptr) output.sort_seconds = chain.zsort()->sort_seconds();
    output.closest_mrays_per_s = chain.trace_times().closest_mrays_per_s();
    output.any_mrays_per_s = chain.trace_times().any_mrays_per_s();
    output.hit_rates = chain.hit_rates().snapshot();
  }
  output.image = film.resolve(plan.image.samples_per_pixel);
  output.rejected_contributions = film.rejected_contributions();
  return output;
}

}  // namespace wavetrace
