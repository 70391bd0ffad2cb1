// One call from a plan and a world to an image: the chain run through the pipeline (or the
// megakernel), with what each stage did.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "wavetrace/scene/camera.hpp"
#include "wavetrace/stages/hit_rates.hpp"
#include "wavetrace/pipeline/pipeline.hpp"
#include "wavetrace/setup/render_plan.hpp"
#include "wavetrace/stages/generate.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

struct RenderOutput {
  PipelineRun run;
  std::vector<float> image;  // linear RGB, top row first
  std::vector<DepthHitRate> hit_rates;  // closest-hit rays per path depth
  // Set when [memory] asks for observation but the accelerator's reads cannot be seen.
  std::optional<std::string> memory_unobserved;
  double sort_seconds = 0.0;  // zsort's sorting alone (within its stage seconds)
  double closest_mrays_per_s = 0.0;  // trace's closest-hit (camera and bounce) rays per busy second
  double any_mrays_per_s = 0.0;      // trace's shadow rays per busy second
  std::uint64_t rejected_contributions = 0;
};

// How one render shares its image with others (a distributed render): which camera rays it
// generates, and how its film's fixed-point sums are combined with theirs before the image
// is resolved (in place; the sum over processes is exactly one process's film). Left empty:
// the whole image, alone.
struct ImageShare {
  CameraRaySource camera_rays;
  std::function<void(std::vector<std::int64_t>& film_sums)> combine_film;
};

RenderOutput render_image(const RenderPlan& plan, const World& world, const Camera& camera,
                          const std::function<void(const Progress&)>& on_progress = {},
                          const ImageShare& share = {});

}  // namespace wavetrace
