// What every bench driver's JSON shares: a measured value that may be absent is its value or
// null, never a made-up zero.
#pragma once

#include <optional>

#include <nlohmann/json.hpp>

namespace wavetrace {

template <typename T>
nlohmann::json json_or_null(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

}  // namespace wavetrace
