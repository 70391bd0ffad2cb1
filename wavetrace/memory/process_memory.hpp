// The process's memory as the OS counts it (Linux /proc): what reports and benchmarks quote
// as resident and peak bytes, never sums of array sizes.
#pragma once

#include <cstddef>

namespace wavetrace {

struct ResidentMemory {
  std::size_t current_bytes = 0;  // VmRSS
  std::size_t peak_bytes = 0;     // VmHWM: the most resident at once since start or the last reset
};

// Zeros where /proc/self/status cannot be read (not Linux).
ResidentMemory read_resident_memory();

// Starts a new peak window: VmHWM becomes the current VmRSS (writes 5 to
// /proc/self/clear_refs). Returns false where the kernel does not allow it; the peak then
// still counts from the start of the process.
bool reset_peak_resident_memory();

// MemAvailable of /proc/meminfo: what the machine can still give without swapping; 0 where
// it cannot be read.
std::size_t available_memory_bytes();

// AnonHugePages of /proc/self/smaps_rollup: the process's anonymous memory on transparent huge
// pages, which shows whether the advice to use them took; 0 where it cannot be read.
std::size_t anonymous_huge_page_bytes();

}  // namespace wavetrace
