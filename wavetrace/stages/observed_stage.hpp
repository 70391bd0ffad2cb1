// The stages whose accelerator reads a [memory] observation counts, each a pager and cache
// client of its own (pipeline/memory_observation.hpp keeps the pager and caches).
#pragma once

#include <cstddef>
#include <string>

namespace wavetrace {

enum class ObservedStage : std::size_t { trace = 0, approx_hit = 1 };
inline constexpr std::size_t kObservedStageCount = 2;
// A world paged from a file counts one more client: the trace's look-ahead, which reads the
// pages of the sorted batches queued for trace before trace reaches them (its faults are
// the pager's prefetches).
inline constexpr std::size_t kLookAheadClient = kObservedStageCount;
inline constexpr std::size_t kFilePagerClients = kObservedStageCount + 1;

inline std::string to_string(ObservedStage stage) { return stage == ObservedStage::trace ? "trace" : "approx_hit"; }

}  // namespace wavetrace
