// From settings to an image, in one include: the plan (render_plan.hpp) and its key table
// (plan_render.hpp), the world it renders (world_setup.hpp, built_world.hpp), the stage chain
// (stage_chain.hpp) and the call that runs it (render_image.hpp). docs/library.md walks
// through them.
#pragma once

#include "wavetrace/setup/built_world.hpp"
#include "wavetrace/setup/plan_render.hpp"
#include "wavetrace/setup/render_image.hpp"
#include "wavetrace/setup/render_plan.hpp"
#include "wavetrace/setup/stage_chain.hpp"
#include "wavetrace/setup/world_setup.hpp"
