// Counts and offsets that can pass 2^32 at a billion triangles, narrowed into the 32-bit
// fields of the compact formats: a clear error naming the field and its limit, never a
// wrapped index that traverses garbage.
#pragma once

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string_view>

#include <fmt/format.h>

namespace wavetrace {

// `what` names the field and what to change, e.g. "hmq block offset (in 4-byte words); build
// in smaller chunks (build.chunk_triangles)".
inline std::uint32_t checked_uint32(std::uint64_t value, std::string_view what) {
  if (value > std::numeric_limits<std::uint32_t>::max()) {
    throw std::length_error(fmt::format("{} is {}, beyond its 32-bit field (at most {})", what, value,
                                        std::numeric_limits<std::uint32_t>::max()));
  }
  return static_cast<std::uint32_t>(value);
}

}  // namespace wavetrace
