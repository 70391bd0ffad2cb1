// Every config key and the option it sets, in one table (plan_keys.cpp): the only place a
// key is read into the typed plan. Checks across keys come after, in plan_render and the
// readers below.
#pragma once

#include <span>
#include <string_view>

#include "wavetrace/stages/render_plan.hpp"

namespace wavetrace {

struct PlanKey {
  std::string_view key;
  void (*read)(const Config& config, std::string_view key, RenderPlan& plan);
};

// One row per key of config_schema(), in an order where a row may read what earlier rows set.
std::span<const PlanKey> plan_keys();

// Applies the rows whose key starts with `prefix` ("" for every row).
void read_plan_keys(const Config& config, RenderPlan& plan, std::string_view prefix = "");

// The checks across an accelerator's keys (widths, conflicting keys) and memory's (page size,
// file backing, cache geometry); throw ConfigError naming the keys.
void check_accelerator_options(const Config& config, const AcceleratorOptions& options);
void check_memory_plan(const Config& config, const MemoryPlan& plan);

// The accel.* and build.* keys as options for make_accelerator, checked (widths, conflicts).
AcceleratorOptions accelerator_options(const Config& config);
// What the config asks of accel.type = auto and of pixel error bounds.
AccelGoal accel_goal(const Config& config);
// memory.*, checked: throws ConfigError naming the key on a bad budget, page size or cache.
MemoryPlan plan_memory(const Config& config);

}  // namespace wavetrace
