// Eight AVX2 lanes put in order without a branch: the children a wide node's slab test
// entered, nearest last (so the nearest ends on top of a stack), by a bitonic network over
// integer keys. Both 8-wide walks (the float nodes of bvh:width=8 and the quantized nodes of
// HMQ and Ray-Strips) push their children with it.
#pragma once

#include "wavetrace/build_config.hpp"

#if WAVETRACE_AVX2

#include <array>

#include <immintrin.h>

#include "wavetrace/kernels/kernel_isa.hpp"

namespace wavetrace::lane_sort {

// Bitonic network over eight int32 lanes, descending: per stage, lane i meets lane i ^ j
// and keeps the larger or the smaller.
struct SortStage {
  int partner[8];
  int take_max[8];
};
inline constexpr std::array<SortStage, 6> kDescendingStages = [] {
  std::array<SortStage, 6> stages{};
  int n = 0;
  for (int k = 2; k <= 8; k *= 2) {
    for (int j = k / 2; j >= 1; j /= 2, ++n) {
      for (int i = 0; i < 8; ++i) {
        stages[n].partner[i] = i ^ j;
        const bool upper = (i & j) != 0, descending_block = (i & k) != 0;
        stages[n].take_max[i] = (upper != descending_block) ? 0 : -1;
      }
    }
  }
  return stages;
}();

[[gnu::always_inline]] inline __m256i sort_descending(__m256i keys) {
  for (const SortStage& stage : kDescendingStages) {
    const __m256i other =
        _mm256_permutevar8x32_epi32(keys, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(stage.partner)));
    keys = _mm256_blendv_epi8(_mm256_min_epi32(keys, other), _mm256_max_epi32(keys, other),
                              _mm256_loadu_si256(reinterpret_cast<const __m256i*>(stage.take_max)));
  }
  return keys;
}

// All bits of lane k set where bit k of `mask` is.
[[gnu::always_inline]] inline __m256i lanes_of(unsigned mask) {
  return _mm256_cmpgt_epi32(_mm256_and_si256(_mm256_set1_epi32(int(mask)), _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128)),
                            _mm256_setzero_si256());
}

// The children in `entered`, farthest first (so the nearest ends on top of a stack): a key
// is the entry distance's bits (>= 0, so they order as integers) with the lane in the low
// three, lanes not entered -1, sorted descending.
[[gnu::always_inline]] inline __m256i nearest_last(__m256 near, unsigned entered) {
  const __m256i keys = _mm256_blendv_epi8(
      _mm256_set1_epi32(-1),
      _mm256_or_si256(_mm256_and_si256(_mm256_castps_si256(near), _mm256_set1_epi32(~7)),
                      _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)),
      lanes_of(entered));
  return _mm256_and_si256(sort_descending(keys), _mm256_set1_epi32(7));
}

#if WAVETRACE_AVX512_DISPATCH
// Lane k of each stage's take_max as bit k: the network's blends as AVX-512 write masks.
inline constexpr std::array<unsigned char, 6> kTakeMaxMasks = [] {
  std::array<unsigned char, 6> masks{};
  for (std::size_t n = 0; n < kDescendingStages.size(); ++n) {
    for (int i = 0; i < 8; ++i) masks[n] |= kDescendingStages[n].take_max[i] ? 1u << i : 0u;
  }
  return masks;
}();

// nearest_last for the AVX-512 walks: the entered lanes and each stage's choice as mask
// registers, a masked max in place of min, max and blend. The same keys, so the same order.
// Not always_inline: only a function of this target may inline it (kernel_isa.hpp).
[[WAVETRACE_AVX512_TARGET]] inline __m256i nearest_last_avx512(__m256 near, unsigned entered) {
  __m256i keys = _mm256_mask_blend_epi32(
      static_cast<__mmask8>(entered), _mm256_set1_epi32(-1),
      _mm256_or_si256(_mm256_and_si256(_mm256_castps_si256(near), _mm256_set1_epi32(~7)),
                      _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
  for (std::size_t n = 0; n < kDescendingStages.size(); ++n) {
    const __m256i other = _mm256_permutevar8x32_epi32(
        keys, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kDescendingStages[n].partner)));
    keys = _mm256_mask_max_epi32(_mm256_min_epi32(keys, other), kTakeMaxMasks[n], keys, other);
  }
  return _mm256_and_si256(keys, _mm256_set1_epi32(7));
}
#endif

// nearest_last in the walk's kernel set.
template <KernelIsa kIsa>
[[gnu::always_inline]] inline __m256i nearest_last_for(__m256 near, unsigned entered) {
#if WAVETRACE_AVX512_DISPATCH
  if constexpr (kIsa == KernelIsa::avx512) return nearest_last_avx512(near, entered);
#endif
  return nearest_last(near, entered);
}

}  // namespace wavetrace::lane_sort

#endif
