// Plan to owned world: a scene built, or a world file opened.
#include "wavetrace/setup/built_world.hpp"

#include <chrono>

#include <fmt/format.h>

#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/setup/world_file.hpp"
#include "wavetrace/setup/world_setup.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"

namespace wavetrace {

BuiltWorld::BuiltWorld(const RenderPlan& plan, std::string* activity, CheckedPages checked) : plan_(plan) {
  std::string ignored;
  std::string& doing = activity != nullptr ? *activity : ignored;
  if (is_world_file(plan_.scene.source)) {
    doing = fmt::format("loading the world {}", plan_.scene.source);
    open_world_file(checked);
  } else {
    if (plan_.memory.file_backing || plan_.memory.copy_world) {
      throw ConfigError(fmt::format("memory.backing = {} {} a world file; {} is not one (make one with wavetrace build)",
                                    plan_.memory.file_backing ? "file" : "copy",
                                    plan_.memory.file_backing ? "pages" : "copies", plan_.scene.source));
    }
    build_from_scene(doing);
  }
}

BuiltWorld::~BuiltWorld() = default;

const SectionFile* BuiltWorld::world_file() const { return loaded_ ? loaded_->file.get() : nullptr; }

void BuiltWorld::open_world_file(CheckedPages checked) {
  loaded_ = load_world(plan_.scene.source, world_paging(plan_), plan_.pipeline.threads, checked, world_holding(plan_));
  loaded_->accelerator->use_isa(parse_kernel_isa(plan_.accelerator.isa));
  phases_.load_seconds = loaded_->seconds;
  phases_.after_load_bytes = phases_.after_build_bytes = read_resident_memory().current_bytes;
  plan_.accelerator.type = loaded_->type;
  if (plan_.needs_proxy() && !loaded_->proxy) {
    throw ConfigError(fmt::format("{} was saved without a proxy, which the chain's approx_hit needs: build it with --proxy",
                                  plan_.scene.source));
  }
  // A data-mode rank judges a coarser proxy by the saved one: judged by the world, its test
  // rays would walk every chunk, which the rank does not hold.
  if (plan_.needs_proxy()) {
    coarsen_world_proxy(*loaded_, plan_.proxy.share, plan_.pipeline.threads,
                        plan_.distribute.mode == DistributeMode::data ? ProxyJudge::saved_proxy
                                                                      : ProxyJudge::whole_world);
  }
  camera_ = resolve_camera(plan_.camera, loaded_->scene);
  world_.emplace(World{loaded_->scene, *loaded_->accelerator, *loaded_->lights,
                       plan_.needs_proxy() ? loaded_->proxy.get() : nullptr, loaded_->file->pager()});
}

void BuiltWorld::build_from_scene(std::string& activity) {
  activity = fmt::format("loading {}", plan_.scene.source);
  const auto load_start = std::chrono::steady_clock::now();
  SceneForWorld loaded = load_scene_for_world(plan_, plan_.needs_proxy());
  scene_ = std::make_unique<Scene>(std::move(loaded.scene));
  camera_ = loaded.camera;
  resolved_ = std::move(loaded.accelerator);
  plan_.accelerator = resolved_->options;
  phases_.load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  phases_.after_load_bytes = read_resident_memory().current_bytes;

  activity = fmt::format("building '{}' over {} triangles", plan_.accelerator.type, scene_->triangle_count);
  accelerator_ = build_world_accelerator(*scene_, plan_.accelerator);
  lights_ = std::make_unique<LightSampler>(represented_lights(*scene_, *accelerator_));
  activity = fmt::format("building the proxy of {} triangles", scene_->triangle_count);
  proxy_ = build_proxy(plan_, *scene_, *accelerator_);
  // A structure holding its own geometry needs the mesh no longer (shading reads the
  // accelerator's surface).
  if (holds_own_geometry(plan_.accelerator.type)) scene_->release_mesh();
  phases_.after_build_bytes = read_resident_memory().current_bytes;
  world_.emplace(World{*scene_, *accelerator_, *lights_, proxy_.get()});
}

ChunkSet* BuiltWorld::chunk_set() {
  Accelerator* accelerator = loaded_ ? loaded_->accelerator.get() : accelerator_.get();
  return accelerator != nullptr ? accelerator->chunk_set() : nullptr;
}

void BuiltWorld::drop_resident_world_pages() const {
  if (loaded_) loaded_->file->drop_resident_pages();
}

}  // namespace wavetrace
