// The benchmark's ray sets, made once and traced by every accelerator: primary (camera),
// diffuse (first bounces off primary hits), shadow (primary hits toward light samples),
// random (from a sphere around the scene to points inside it).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/memory/ray_batch.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

enum class RaySetKind { primary, diffuse, shadow, random };
RaySetKind parse_ray_set_kind(const std::string& text);
std::string to_string(RaySetKind kind);

struct RaySet {
  RaySetKind kind;
  std::vector<std::unique_ptr<RayBatch>> batches;
  std::size_t count() const;
  bool any_hit() const { return kind == RaySetKind::shadow; }
};

// `reference` supplies the primary hits that diffuse and shadow rays start from. A scene
// without emissive triangles gets shadow rays toward a virtual square light above it.
// Throws std::runtime_error if no primary ray hits the scene (diffuse, shadow). Shadow rays
// aim at `scene_lights`, or at the scene's own when null (which needs its mesh or stream).
RaySet make_ray_set(RaySetKind kind, const Scene& scene, const Accelerator& reference, std::size_t count,
                    std::size_t batch_size = kDefaultBatchCapacity, const LightSampler* scene_lights = nullptr);

// Every ray of the set traced by `accelerator` into one HitBatch per ray batch. With
// `coherent`, primary rays go through intersect_coherent (packets where there are any).
std::vector<std::unique_ptr<HitBatch>> trace_ray_set(const Accelerator& accelerator, const RaySet& rays,
                                                     bool coherent = false);
// The hit batches trace_ray_set fills, made once: a timed trace into them neither allocates
// nor first touches its output (on this machine's VM a page's first touch is a hypervisor
// round trip, up to a fifth of a fast accelerator's 30 ms pass).
std::vector<std::unique_ptr<HitBatch>> make_hit_batches(const RaySet& rays);
void trace_ray_set(const Accelerator& accelerator, const RaySet& rays, std::vector<std::unique_ptr<HitBatch>>& hits,
                   bool coherent = false);
// The same with every read reported to `observers` (as client 0); needs accelerator.probed().
std::vector<std::unique_ptr<HitBatch>> trace_ray_set_probed(const Accelerator& accelerator, const RaySet& rays,
                                                            const MemoryObservers& observers);

}  // namespace wavetrace
