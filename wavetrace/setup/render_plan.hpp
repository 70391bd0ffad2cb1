// The plan of a render: every setting of a checked config, typed (read by the key table in
// config_keys.cpp; plan_render.hpp makes one), and the stage chain it names.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/accel_choice.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/stages/generate.hpp"
#include "wavetrace/pipeline/memory_observation.hpp"
#include "wavetrace/stages/path_rules.hpp"
#include "wavetrace/stages/photon_rules.hpp"
#include "wavetrace/pipeline/pipeline.hpp"
#include "wavetrace/stages/zsort.hpp"

namespace wavetrace {

// camera.*: each set key overrides the scene's own camera (or the one framing its bounds).
struct CameraOverride {
  std::optional<glm::vec3> position, look_at, up;
  std::optional<float> vertical_fov_degrees;
  bool operator==(const CameraOverride&) const = default;
};

// distribute.*: how the ranks of a render started by mpirun share it (wavetrace/distribute/);
// a process started alone renders the whole image whatever they say.
enum class DistributeMode { image, data };
DistributeMode parse_distribute_mode(const std::string& text);
std::string to_string(DistributeMode mode);
// Data mode deals runs of chunks equal in triangles (memory) or in a probe's rays (work).
enum class DistributeBalance { bytes, triangles, rays };
DistributeBalance parse_distribute_balance(const std::string& text);
std::string to_string(DistributeBalance balance);
struct DistributePlan {
  DistributeMode mode = DistributeMode::image;
  std::uint64_t range_rays = 0;  // camera rays handed out at a time (0: chosen from the image and ranks)
  double replicate = 0.0;        // data mode: share of the triangles every rank answers itself
  DistributeBalance balance = DistributeBalance::bytes;  // data mode: what the ranks' chunks are weighed by
  bool operator==(const DistributePlan&) const = default;
};

struct RenderPlan {
  SceneRequest scene;
  CameraOverride camera;
  ImageSpec image;
  PixelOrder pixel_order = PixelOrder::zcurve;
  bool film_per_thread = false;  // render.film
  PathRules rules;
  Integrator integrator = Integrator::path;  // render.integrator
  PhotonOptions photon;
  PipelineOptions pipeline;
  AcceleratorOptions accelerator;  // type "auto" until resolve_accelerator chooses
  AccelGoal accel_goal;
  MemoryPlan memory;
  ProxyOptions proxy;
  ZSortOptions reorder;
  std::vector<std::string> stages = {"auto"};  // pipeline.stages, "auto" expanded by stages_for
  DistributePlan distribute;
  bool needs_proxy() const;
  bool operator==(const RenderPlan&) const = default;
};

// The chain pipeline.stages = auto stands for: generate, [approx_hit], [zsort], trace,
// shade, spawn, with approx_hit for hit-point heuristics and zsort for any but none.
std::vector<std::string> stages_for(ReorderHeuristic heuristic);

// Worker threads the plan runs on: render.threads, or every core for 0.
int worker_count(const PipelineOptions& options);

}  // namespace wavetrace
