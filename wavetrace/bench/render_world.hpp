// The world a rendering benchmark shares across its renders: a saved world mapped (or
// paged) from its file, or a scene loaded and built once, with lights and, when asked, the
// proxy hit-point heuristics need.
#pragma once

#include <memory>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/scene.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/stages/world.hpp"
#include "wavetrace/setup/world_file.hpp"

namespace wavetrace {

// One heuristic's render of a benchmark's config. No reordering has no zsort and so no
// buffer: a disk buffer asked of the others is not asked of it.
Config heuristic_variant(const Config& config, ReorderHeuristic heuristic);

class RenderWorld {
 public:
  // Throws ConfigError where the plan cannot be met (a world file without the proxy asked
  // for, file paging of a scene that is not a world file).
  RenderWorld(const RenderPlan& base, bool needs_proxy);

  const Scene& scene() const { return saved_ ? saved_->scene : built_scene_; }
  const Accelerator& accelerator() const { return saved_ ? *saved_->accelerator : *built_accelerator_; }
  const Proxy* proxy() const { return saved_ ? saved_->proxy.get() : built_proxy_.get(); }
  const LoadedWorld* saved() const { return saved_.get(); }
  FilePager* file_pager() const { return saved_ ? saved_->file->pager() : nullptr; }
  World world() const;

 private:
  std::unique_ptr<LoadedWorld> saved_;
  Scene built_scene_;
  std::unique_ptr<Accelerator> built_accelerator_;
  std::unique_ptr<LightSampler> built_lights_;
  std::unique_ptr<Proxy> built_proxy_;
};

}  // namespace wavetrace
