// A world built from a plan and owned whole: the scene (loaded, or a saved world file mapped
// or paged from disk), its accelerator (auto resolved), the lights on the surface that
// accelerator represents, the proxy when the chain needs one, and the camera. What
// `wavetrace render` builds before it renders, and a library user's entry point.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/scene/camera.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/scene.hpp"
#include "wavetrace/setup/accel_choice.hpp"
#include "wavetrace/setup/render_plan.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {

struct LoadedWorld;

// What building took, as the OS saw it.
struct WorldPhases {
  double load_seconds = 0.0;  // the scene load (a streamed scene: its bounds pass) or the world file's
  std::size_t after_load_bytes = 0, after_build_bytes = 0;  // resident memory
};

class BuiltWorld {
 public:
  // Throws ConfigError, SceneError or SectionFileError naming what is wrong. `activity`,
  // when given, is kept up to date with what is being done (for an out-of-memory message).
  // `checked`: what loading a world file leaves resident (section_file.hpp; given back by a
  // data-parallel rank).
  explicit BuiltWorld(const RenderPlan& plan, std::string* activity = nullptr,
                      CheckedPages checked = CheckedPages::kept);
  ~BuiltWorld();
  BuiltWorld(const BuiltWorld&) = delete;
  BuiltWorld& operator=(const BuiltWorld&) = delete;

  // What every stage reads; valid while this object lives.
  const World& world() const { return *world_; }
  const Scene& scene() const { return world_->scene; }
  const Camera& camera() const { return camera_; }
  // The plan with the accelerator as built: auto's choice, a pixel epsilon, a world file's type.
  const RenderPlan& plan() const { return plan_; }
  // What auto or a pixel bound resolved to; null for a world file.
  const ResolvedAccelerator* resolution() const { return resolved_ ? &*resolved_ : nullptr; }
  const WorldPhases& phases() const { return phases_; }
  // The world file the world was loaded from; null for a scene built now.
  const SectionFile* world_file() const;
  // The chunks of a chunked world (for a data-parallel render to own and route); null for
  // any other world.
  ChunkSet* chunk_set();
  // A mapped world file gives back the pages its load touched (checking every chunk reads
  // them all): a data-parallel rank then holds only the chunks it answers for.
  void drop_resident_world_pages() const;

 private:
  void build_from_scene(std::string& activity);
  void open_world_file(CheckedPages checked);

  RenderPlan plan_;
  std::unique_ptr<LoadedWorld> loaded_;  // a world file
  std::unique_ptr<Scene> scene_;
  std::unique_ptr<Accelerator> accelerator_;
  std::unique_ptr<LightSampler> lights_;
  std::unique_ptr<Proxy> proxy_;
  Camera camera_;
  std::optional<ResolvedAccelerator> resolved_;
  std::optional<World> world_;
  WorldPhases phases_;
};

}  // namespace wavetrace
