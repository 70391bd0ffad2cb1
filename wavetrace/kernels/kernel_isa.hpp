// The sets of walks compiled into this binary: the build's own (-march, x86-64-v3 by default:
// AVX2) and, in an AVX2 build, the same walks compiled for AVX-512, and the call that runs a
// walk in one of them. Which one runs is chosen at start (memory/kernel_isa_choice.hpp).
#pragma once

#include "wavetrace/build_config.hpp"

// Kernels written for sixteen lanes (__m512 vectors passed between shared helpers), compiled
// only where they inline into the AVX-512 walks. Clang refuses any call that passes a __m512
// from a function not of that target, which such shared code is, so a Clang build (the
// sanitizer build) keeps their eight-lane passes there too (the same hits).
#if WAVETRACE_AVX512_DISPATCH && !defined(__clang__)
#define WAVETRACE_SIXTEEN_LANES 1
#else
#define WAVETRACE_SIXTEEN_LANES 0
#endif

namespace wavetrace {

enum class KernelIsa : unsigned char {
  baseline,  // the build's -march
  avx512,    // only in a build with WAVETRACE_AVX512_DISPATCH
};

// Calls `walk.operator()<isa>()` compiled for `isa`: with AVX-512, every function it calls is
// inlined into one function of that target (flatten), so the walks' AVX2 intrinsics and vector
// code are compiled again in EVEX form with 32 vector registers, and their own AVX-512
// paths (chosen by the KernelIsa template argument) inline where they are called. Nothing it
// inlines is emitted as a shared copy, so no function the baseline calls can end up compiled
// for AVX-512; what GCC cannot inline stays a call to the baseline's copy.
#if WAVETRACE_AVX512_DISPATCH
template <typename Walk>
[[WAVETRACE_AVX512_TARGET, gnu::flatten]] void walk_with_avx512(Walk& walk) {
  walk.template operator()<KernelIsa::avx512>();
}
#endif

template <typename Walk>
[[gnu::always_inline]] inline void walk_with(KernelIsa isa, Walk&& walk) {
#if WAVETRACE_AVX512_DISPATCH
  if (isa == KernelIsa::avx512) return walk_with_avx512(walk);
#endif
  walk.template operator()<KernelIsa::baseline>();
}

}  // namespace wavetrace
