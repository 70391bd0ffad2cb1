// The shared, read-only world every stage sees: scene, main accelerator, lights, proxy.
#pragma once

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/memory/file_pager.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

struct World {
  const Scene& scene;
  const Accelerator& accelerator;
  const LightSampler& lights;
  const Proxy* proxy = nullptr;  // for approx_hit; absent when the chain has none
  FilePager* pager = nullptr;    // the real pager, when the world is a world file paged from disk
};

// The scene's lights on the surface `accelerator` answers for (its represented_point).
inline LightSampler represented_lights(const Scene& scene, const Accelerator& accelerator) {
  return LightSampler(scene, [&](const glm::vec3& point) { return accelerator.represented_point(point); });
}

}  // namespace wavetrace
