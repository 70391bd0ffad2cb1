// A small render for the tests: the scene's accelerator, lights and (when the chain asks for
// it) proxy built from `settings`, then render_image.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace::testing {

// `share`: the part of a shared image this render takes (render_image's ImageShare).
inline RenderOutput render_scene(const Scene& scene, const std::vector<std::string>& settings,
                                 const ImageShare& share = {}) {
  Config config;
  for (const std::string& setting : settings) config.set(setting);
  const RenderPlan plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, plan.accelerator);
  const LightSampler lights(scene);
  const std::unique_ptr<Proxy> proxy = build_proxy(plan, scene, *accelerator);
  return render_image(plan, World{scene, *accelerator, lights, proxy.get()}, resolve_camera(plan.camera, scene), {},
                      share);
}

}  // namespace wavetrace::testing
