// From a checked config to a running render: the plan (every setting, typed), the stage
// chain it names, and one call that renders an image through the pipeline.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "accel/registry.hpp"
#include "stages/accel_choice.hpp"
#include "scene/scene.hpp"
#include "stages/config.hpp"
#include "stages/film.hpp"
#include "stages/generate.hpp"
#include "stages/hit_rates.hpp"
#include "stages/trace.hpp"
#include "stages/memory_observation.hpp"
#include "stages/zsort.hpp"
#include "accel/proxy/proxy.hpp"
#include "stages/path_rules.hpp"
#include "stages/pipeline.hpp"
#include "stages/world.hpp"

namespace wavetrace {

struct CameraOverride {
  std::optional<glm::vec3> position, look_at, up;
  std::optional<float> vertical_fov_degrees;
};

struct RenderPlan {
  SceneRequest scene;
  CameraOverride camera;
  ImageSpec image;
  PixelOrder pixel_order = PixelOrder::scanline;
  bool film_per_thread = false;  // render.film
  PathRules rules;
  PipelineOptions pipeline;
  AcceleratorOptions accelerator;  // type "auto" until resolve_accelerator chooses
  AccelGoal accel_goal;
  MemoryPlan memory;
  ProxyOptions proxy;
  ZSortOptions reorder;
  std::vector<std::string> stages;
  bool needs_proxy() const;
};

// The chain pipeline.stages = auto stands for: generate, [approx_hit], [zsort], trace,
// shade, spawn, with approx_hit for hit-point heuristics and zsort for any but none.
std::vector<std::string> stages_for(ReorderHeuristic heuristic);

// The proxy the plan's chain needs (approx_hit), built against the scene's accelerator;
// null when the chain has no approx_hit.
std::unique_ptr<Proxy> build_proxy(const RenderPlan& plan, const Scene& scene, const Accelerator& accelerator);

// The accel.* keys as options for make_accelerator.
AcceleratorOptions accelerator_options(const Config& config);

// The scene's accelerator (make_world_accelerator): from its generators when the scene is
// streamed, else from its mesh, which must then outlive the accelerator.
std::unique_ptr<Accelerator> build_world_accelerator(const Scene& scene, const AcceleratorOptions& options);

// Before anything is allocated: throws SceneError when a builtin scene of the requested
// size would not fit in the memory the machine has available, by the accelerator's bytes
// per triangle (and the whole mesh's, when the scene is not streamed).
void check_scene_fits(const RenderPlan& plan);

// A scene loaded for building its world, and the accelerator it is built with: the plan's,
// or what accel.type = auto and pixel error bounds resolve to on this scene and camera. The
// scene is generated streamed when the type (or auto) may build from a stream and no mesh
// is wanted (`keep_mesh`: a proxy is simplified from it), and loaded again whole when the
// chosen type reads the mesh in place.
struct SceneForWorld {
  Scene scene;
  Camera camera;
  ResolvedAccelerator accelerator;
};
SceneForWorld load_scene_for_world(const RenderPlan& plan, bool keep_mesh);

// Reads every key; throws ConfigError for a stage list that cannot run.
RenderPlan plan_render(const Config& config);

// The camera: the config's keys over the scene's own camera over one framing the bounds.
Camera resolve_camera(const CameraOverride& override, const Scene& scene);

// Owns the stage objects a plan names, in chain order (generate excluded).
class StageChain {
 public:
  StageChain(const RenderPlan& plan, const World& world, Film& film, const MemoryObservers* observers = nullptr);
  std::vector<const Stage*> stages() const;
  bool loops() const { return loops_; }
  const HitRateCounters& hit_rates() const { return hit_rates_; }
  const ZSortStage* zsort() const { return zsort_; }
  const TraceTimes& trace_times() const { return trace_times_; }

 private:
  std::vector<std::unique_ptr<Stage>> owned_;
  HitRateCounters hit_rates_;
  TraceTimes trace_times_;
  const ZSortStage* zsort_ = nullptr;
  bool loops_ = false;
};

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

RenderOutput render_image(const RenderPlan& plan, const World& world, const Camera& camera,
                          const std::function<void(const Progress&)>& on_progress = {});

}  // namespace wavetrace
