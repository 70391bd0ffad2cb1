// The shared, read-only world every stage sees: scene, main accelerator, lights.
#pragma once

#include "accel/accelerator.hpp"
#include "scene/lights.hpp"
#include "scene/scene.hpp"

namespace wavetrace {

struct World {
  const Scene& scene;
  const Accelerator& accelerator;
  const LightSampler& lights;
};

}  // namespace wavetrace
