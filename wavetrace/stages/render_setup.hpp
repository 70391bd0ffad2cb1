// From settings to an image, in one include: the plan (render_plan.hpp) and its key table
// (plan_keys.hpp), the world it renders (world_setup.hpp, built_world.hpp), the stage chain
// (stage_chain.hpp) and the call that runs it (render_image.hpp). docs/library.md walks
// through them.
#pragma once

#include "wavetrace/stages/built_world.hpp"
#include "wavetrace/stages/plan_keys.hpp"
#include "wavetrace/stages/render_image.hpp"
#include "wavetrace/stages/render_plan.hpp"
#include "wavetrace/stages/stage_chain.hpp"
#include "wavetrace/stages/world_setup.hpp"
