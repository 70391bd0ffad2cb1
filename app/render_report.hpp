// What a render reports: the stage table on stdout and the --stats JSON.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "accel/accelerator.hpp"
#include "scene/scene.hpp"
#include "stages/render_setup.hpp"

namespace wavetrace {

struct RenderFacts {
  const Scene& scene;
  const Accelerator& accelerator;
  const RenderPlan& plan;
  const RenderOutput& output;
  std::string image_path;
  const Proxy* proxy = nullptr;
};

nlohmann::json proxy_json(const Proxy& proxy);

nlohmann::json render_stats_json(const RenderFacts& facts);
std::string render_table(const RenderFacts& facts);

nlohmann::json bounds_json(const Bounds3& bounds);
nlohmann::json pager_json(const PagerStats& pager);
nlohmann::json cache_json(const CacheStats& cache);

}  // namespace wavetrace
