// Config to plan: each key read into the typed plan by its row of the key table
// (config_keys.cpp), then the checks across keys in plan_render and the readers below.
#pragma once

#include <string_view>

#include "wavetrace/setup/render_plan.hpp"

namespace wavetrace {

// Reads every key (config_schema()'s rows) and checks them together; throws ConfigError for
// settings that conflict and a stage list that cannot run.
RenderPlan plan_render(const Config& config);

// The most rays one camera ray becomes at once in the plan's chain (the largest of its
// stages' rays_out_per_ray, read from the stages' own counts before they exist): sizes the
// flight budget a disk buffer needs to fill.
std::size_t rays_per_camera_ray(const RenderPlan& plan);

// What a world file keeps of the accelerator the plan built: accel.type and the keys of its
// section whose rows record a value (widths, modes, error bounds auto or a pixel bound chose).
void record_built_accelerator(Config& config, const RenderPlan& plan);

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
