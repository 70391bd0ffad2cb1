// The shared, read-only world every stage sees: scene, main accelerator, lights, proxy.
#pragma once

#include "accel/accelerator.hpp"
#include "accel/proxy/proxy.hpp"
#include "memory/file_pager.hpp"
#include "scene/lights.hpp"
#include "scene/scene.hpp"

namespace wavetrace {

struct World {
  const Scene& scene;
  const Accelerator& accelerator;
  const LightSampler& lights;
  const Proxy* proxy = nullptr;  // for approx_hit; absent when the chain has none
  FilePager* pager = nullptr;    // the real pager, when the world is a world file paged from disk
};

}  // namespace wavetrace
