// One call from a plan and a world to an image: the chain run through the pipeline (or the
// megakernel), with what each stage did.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/scene/camera.hpp"
#include "wavetrace/stages/hit_rates.hpp"
#include "wavetrace/pipeline/pipeline.hpp"
#include "wavetrace/setup/render_plan.hpp"
#include "wavetrace/stages/generate.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

// The photon pass of render.integrator = photon, before the camera pass.
struct PhotonPassReport {
  PipelineRun run;              // emit_photons first, then its chain
  std::uint64_t emitted = 0;    // photons that left the lights
  std::size_t global_photons = 0, caustic_photons = 0;  // what the maps hold
  std::size_t precomputed = 0;  // irradiance estimates precomputed in the global map (photon.precompute)
  double map_seconds = 0.0;     // sorting the deposits, building both kd-trees, precomputing
  float radius = 0.0f;          // photon.radius as resolved
  // A world file paged from disk: the pages read while photons were traced, apart from the
  // camera pass's (its trace stage reports the whole render's, both passes together).
  std::optional<DiskCounters> disk;
};

struct RenderOutput {
  PipelineRun run;  // the camera pass
  std::vector<float> image;  // linear RGB, top row first
  std::vector<DepthHitRate> hit_rates;  // closest-hit rays per path depth
  // Set when [memory] asks for observation but the accelerator's reads cannot be seen.
  std::optional<std::string> memory_unobserved;
  double sort_seconds = 0.0;  // zsort's sorting alone (within its stage seconds)
  double closest_mrays_per_s = 0.0;  // trace's closest-hit (camera and bounce) rays per busy second
  double any_mrays_per_s = 0.0;      // trace's shadow rays per busy second
  std::uint64_t rejected_contributions = 0;
  std::optional<PhotonPassReport> photons;  // render.integrator = photon
  // The whole render's wall time: the camera pass, and the photon pass and its maps if any.
  double seconds() const { return run.seconds + (photons ? photons->run.seconds + photons->map_seconds : 0.0); }
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
