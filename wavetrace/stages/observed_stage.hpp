// The stages whose accelerator reads a [memory] observation counts, each a pager and cache
// client of its own (pipeline/memory_observation.hpp keeps the pager and caches).
#pragma once

#include <cstddef>
#include <string>

namespace wavetrace {

enum class ObservedStage : std::size_t { trace = 0, approx_hit = 1 };
inline constexpr std::size_t kObservedStageCount = 2;

inline std::string to_string(ObservedStage stage) { return stage == ObservedStage::trace ? "trace" : "approx_hit"; }

}  // namespace wavetrace
