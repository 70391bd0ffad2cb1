// What a render reports: the stage table on stdout and the --stats JSON.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "accel/accelerator.hpp"
#include "scene/scene.hpp"
#include "stages/render_setup.hpp"

namespace wavetrace {

// Resident memory read from the OS (VmRSS) at the end of each phase of a render, and the
// process's peak (VmHWM).
struct ProcessMemory {
  std::size_t after_load_bytes = 0;
  std::size_t after_build_bytes = 0;
  std::size_t after_render_bytes = 0;
  std::size_t peak_rss_bytes = 0;
};

struct RenderFacts {
  const Scene& scene;
  const Accelerator& accelerator;
  const RenderPlan& plan;
  const RenderOutput& output;
  std::string image_path;
  const Proxy* proxy = nullptr;
  ProcessMemory memory;
};

nlohmann::json proxy_json(const Proxy& proxy);

nlohmann::json render_stats_json(const RenderFacts& facts);
std::string render_table(const RenderFacts& facts);

nlohmann::json bounds_json(const Bounds3& bounds);
nlohmann::json pager_json(const PagerStats& pager);
nlohmann::json cache_json(const CacheStats& cache);

}  // namespace wavetrace
