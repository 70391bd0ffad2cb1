// The CPU features this build needs (wavetrace/build_config.hpp) against the running CPU's:
// checked as the program starts (cpu_support.cpp), so a CPU without AVX2 gets a clear error,
// not an illegal instruction somewhere in a traversal.
#pragma once

namespace wavetrace {

struct CpuFeatures {
  bool avx2 = false, fma = false, bmi2 = false;
  bool avx512 = false;  // x86-64-v4's F, VL, BW, DQ and CD, with the OS saving their registers
};

// What this build of the library executes (its -march).
CpuFeatures required_cpu_features();
// What the CPU running this process offers.
CpuFeatures running_cpu_features();

// Null when `have` covers `need`; else the message for the first feature missing, naming
// it and what to rebuild with. A static string: the start-up check allocates nothing.
const char* cpu_support_error(const CpuFeatures& have, const CpuFeatures& need);

}  // namespace wavetrace
