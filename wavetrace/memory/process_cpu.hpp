// The process's CPU time as the OS counts it (getrusage): what a render's report quotes beside
// its wall time, so that a render's cost in cores, not only its latency, is measured.
#pragma once

#include <sys/resource.h>

namespace wavetrace {

struct ProcessCpuTime {
  double user_seconds = 0.0;    // all the process's threads, in user mode
  double system_seconds = 0.0;  // and in the kernel (system calls, page faults)

  ProcessCpuTime operator-(const ProcessCpuTime& earlier) const {
    return {user_seconds - earlier.user_seconds, system_seconds - earlier.system_seconds};
  }
};

// Zeros where the OS will not say.
inline ProcessCpuTime read_process_cpu_time() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return {};
  const auto seconds = [](const timeval& t) { return double(t.tv_sec) + double(t.tv_usec) * 1e-6; };
  return {seconds(usage.ru_utime), seconds(usage.ru_stime)};
}

}  // namespace wavetrace
