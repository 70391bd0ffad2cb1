// Opening or building a benchmark's world once.
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/bench/render_world.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"

#include <fmt/format.h>

namespace wavetrace {

Config heuristic_variant(const Config& config, ReorderHeuristic heuristic) {
  Config variant = config;
  variant.set_value("reorder.heuristic", to_string(heuristic));
  if (heuristic == ReorderHeuristic::none) variant.set_value("reorder.buffer", std::string("memory"));
  return variant;
}

RenderWorld::RenderWorld(const RenderPlan& base, bool needs_proxy) {
  if (is_world_file(base.scene.source)) {
    saved_ = load_world(base.scene.source, world_paging(base), base.pipeline.threads, CheckedPages::kept,
                        world_holding(base));
    saved_->accelerator->use_isa(parse_kernel_isa(base.accelerator.isa));
    if (needs_proxy && !saved_->proxy) {
      throw ConfigError(fmt::format("{} was saved without a proxy, which hit-point heuristics need: build it with --proxy",
                                    base.scene.source));
    }
    if (needs_proxy) coarsen_world_proxy(*saved_, base.proxy.share, base.pipeline.threads);
    return;
  }
  if (base.memory.file_backing) throw ConfigError("memory.backing = file pages a world file: give one (wavetrace build)");
  if (base.memory.copy_world) throw ConfigError("memory.backing = copy copies a world file: give one (wavetrace build)");
  built_scene_ = load_scene(base.scene);
  built_accelerator_ = build_world_accelerator(built_scene_, base.accelerator);
  built_lights_ = std::make_unique<LightSampler>(represented_lights(built_scene_, *built_accelerator_));
  if (needs_proxy) built_proxy_ = std::make_unique<Proxy>(built_scene_.mesh, base.proxy, *built_accelerator_);
}

World RenderWorld::world() const {
  return World{scene(), accelerator(), saved_ ? *saved_->lights : *built_lights_, proxy(), file_pager()};
}

}  // namespace wavetrace
