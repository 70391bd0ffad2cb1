// What a render reports: the stage table on stdout and the --stats JSON.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/distribute/shared_render.hpp"
#include "wavetrace/scene/scene.hpp"
#include "wavetrace/setup/render_setup.hpp"

namespace wavetrace {

// What each phase of a render left: resident memory read from the OS (VmRSS) at its end,
// the process's peak (VmHWM), and the load's wall time.
struct RenderPhases {
  std::size_t after_load_bytes = 0;
  std::size_t after_build_bytes = 0;
  std::size_t after_render_bytes = 0;
  std::size_t peak_rss_bytes = 0;
  double load_seconds = 0.0;  // wall time of the scene load (a streamed scene: its bounds pass)
  // A world file's holding: "mapped", "copied" or "paged" ("" for a scene built now), and why
  // a copy asked for was not made.
  std::string world_holding, world_holding_note;
  std::size_t huge_page_bytes = 0;  // AnonHugePages after the render
};

struct RenderFacts {
  const Scene& scene;
  const Accelerator& accelerator;
  const RenderPlan& plan;
  const RenderOutput& output;
  std::string image_path;
  const Proxy* proxy = nullptr;
  RenderPhases phases;
  const AccelChoice* accel_choice = nullptr;  // accel.type = auto: its candidates and reasons
  // A render shared by ranks (mpirun): every rank's report; the stages above are rank 0's.
  const DistributedRender* distributed = nullptr;
};

nlohmann::json proxy_json(const Proxy& proxy);

nlohmann::json render_stats_json(const RenderFacts& facts);
nlohmann::json distribute_json(const DistributedRender& render, const RenderPlan& plan);
std::string render_table(const RenderFacts& facts);

nlohmann::json bounds_json(const Bounds3& bounds);
nlohmann::json pager_json(const PagerStats& pager);
nlohmann::json cache_json(const CacheStats& cache);

}  // namespace wavetrace
