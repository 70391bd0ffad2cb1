// Test helper: accelerator options from a type name and settings, as `--accel` and config
// files give them, so that tests name the accelerators they build the way users do.
#pragma once

#include <sstream>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/setup/plan_render.hpp"

namespace wavetrace::testing {

// `type` is an accelerator name, optionally followed by settings: "hmq accel.hmq.width=8".
inline AcceleratorOptions options_for(const std::string& type) {
  Config config;
  std::istringstream words(type);
  std::string name, setting;
  words >> name;
  config.set("accel.type=" + name);
  while (words >> setting) config.set(setting);
  return accelerator_options(config);
}

}  // namespace wavetrace::testing
