// The start-up check. This file is compiled for baseline x86-64 (CMakeLists.txt) and its
// check runs as an ELF constructor of priority 101, before the library's and the program's
// own static initializers, none of which may run first on a CPU that lacks the build's ISA.
#include "wavetrace/memory/cpu_support.hpp"

#include <unistd.h>

#include <cstring>

// This file alone is compiled for baseline x86-64: build_config.hpp's check that the
// compiler targets the build's ISA does not apply to it.
#define WAVETRACE_BASELINE_TRANSLATION_UNIT 1
#include "wavetrace/build_config.hpp"

namespace wavetrace {
namespace {

#define WAVETRACE_REBUILD_HINT                                                                                  \
  ", which this build of wavetrace needs (-march=" WAVETRACE_ARCH                                               \
  "): rebuild it with -DWAVETRACE_ARCH=x86-64-v2 (no 8-wide traversals) or run it on an x86-64-v3 CPU (AVX2, " \
  "FMA, BMI2)\n"

}  // namespace
}  // namespace wavetrace

// Extern "C" and named so that the library's link interface can ask for it
// (-Wl,--undefined=wavetrace_check_cpu_at_start): a static library's member is linked only
// when something refers to it.
extern "C" __attribute__((constructor(101))) void wavetrace_check_cpu_at_start() {
  using namespace wavetrace;
  const char* error = cpu_support_error(running_cpu_features(), required_cpu_features());
  if (error == nullptr) return;
  [[maybe_unused]] const ssize_t written = write(STDERR_FILENO, error, std::strlen(error));
  _exit(1);
}

namespace wavetrace {

CpuFeatures required_cpu_features() {
  return {WAVETRACE_AVX2 != 0, WAVETRACE_FMA != 0, WAVETRACE_BMI2 != 0, WAVETRACE_AVX512F != 0};
}

CpuFeatures running_cpu_features() {
  __builtin_cpu_init();
  // libgcc's answer for avx512* already asks the OS (XGETBV) whether it saves the ZMM state.
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
                      __builtin_cpu_supports("avx512cd");
  return {__builtin_cpu_supports("avx2") != 0, __builtin_cpu_supports("fma") != 0, __builtin_cpu_supports("bmi2") != 0,
          avx512};
}

const char* cpu_support_error(const CpuFeatures& have, const CpuFeatures& need) {
  if (need.avx2 && !have.avx2) return "wavetrace: error: this CPU has no AVX2" WAVETRACE_REBUILD_HINT;
  if (need.fma && !have.fma) return "wavetrace: error: this CPU has no FMA" WAVETRACE_REBUILD_HINT;
  if (need.bmi2 && !have.bmi2) return "wavetrace: error: this CPU has no BMI2" WAVETRACE_REBUILD_HINT;
  if (need.avx512 && !have.avx512) {
    return "wavetrace: error: this CPU has no AVX-512 (F, VL, BW, DQ, CD), which this build of wavetrace needs "
           "(-march=" WAVETRACE_ARCH "): rebuild it with the default -DWAVETRACE_ARCH=x86-64-v3, whose AVX-512 walks "
           "are chosen at start only where the CPU has them\n";
  }
  return nullptr;
}

}  // namespace wavetrace
