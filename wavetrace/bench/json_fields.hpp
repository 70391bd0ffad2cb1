// What every bench driver's JSON shares: a measured value that may be absent is its value or
// null, never a made-up zero; a build's phases.
#pragma once

#include <optional>

#include <nlohmann/json.hpp>

#include "wavetrace/accel/build_phases.hpp"

namespace wavetrace {

template <typename T>
nlohmann::json json_or_null(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

// {phase: seconds}; the phases' order is the build's, which a JSON object does not keep.
inline nlohmann::json build_phases_json(const BuildPhases& phases) {
  nlohmann::json object = nlohmann::json::object();
  for (const auto& [name, seconds] : phases.entries()) object[name] = seconds;
  return object;
}

}  // namespace wavetrace
