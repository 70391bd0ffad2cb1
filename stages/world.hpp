// The shared, read-only world every stage sees: scene, main accelerator, lights, proxy.
#pragma once

#include "accel/accelerator.hpp"
#include "accel/proxy/proxy.hpp"
#include "scene/lights.hpp"
#include "scene/scene.hpp"

namespace wavetrace {

struct World {
  const Scene& scene;
  const Accelerator& accelerator;
  const LightSampler& lights;
  const Proxy* proxy = nullptr;  // for approx_hit; absent when the chain has none
};

}  // namespace wavetrace
