// 8x8 transposes for packet walks: eight rays' answers for eight children (one row a ray)
// become one row a child, the form a stack entry stores; PacketChildren collects the answers.
#pragma once

#include <cstdint>
#include <limits>

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2

#if WAVETRACE_AVX2
#include <immintrin.h>

#include "wavetrace/kernels/lane_sort.hpp"
#endif

namespace wavetrace {

// Bit j of byte i becomes bit i of byte j (Hacker's Delight, transpose8: three exchanges of
// the blocks off the diagonal, 1x1, 2x2 then 4x4 bits).
[[gnu::always_inline]] inline std::uint64_t transpose_bits_8x8(std::uint64_t x) {
  x = (x & 0xAA55AA55AA55AA55ull) | ((x & 0x00AA00AA00AA00AAull) << 7) | ((x >> 7) & 0x00AA00AA00AA00AAull);
  x = (x & 0xCCCC3333CCCC3333ull) | ((x & 0x0000CCCC0000CCCCull) << 14) | ((x >> 14) & 0x0000CCCC0000CCCCull);
  x = (x & 0xF0F0F0F00F0F0F0Full) | ((x & 0x00000000F0F0F0F0ull) << 28) | ((x >> 28) & 0x00000000F0F0F0F0ull);
  return x;
}

#if WAVETRACE_AVX2
// Lane j of row i becomes lane i of row j: pairs interleaved, then quads, then the halves.
[[gnu::always_inline]] inline void transpose_lanes_8x8(__m256 row[8]) {
  const __m256 t0 = _mm256_unpacklo_ps(row[0], row[1]), t1 = _mm256_unpackhi_ps(row[0], row[1]);
  const __m256 t2 = _mm256_unpacklo_ps(row[2], row[3]), t3 = _mm256_unpackhi_ps(row[2], row[3]);
  const __m256 t4 = _mm256_unpacklo_ps(row[4], row[5]), t5 = _mm256_unpackhi_ps(row[4], row[5]);
  const __m256 t6 = _mm256_unpacklo_ps(row[6], row[7]), t7 = _mm256_unpackhi_ps(row[6], row[7]);
  const __m256 s0 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), s1 = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
  const __m256 s2 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), s3 = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
  const __m256 s4 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(1, 0, 1, 0)), s5 = _mm256_shuffle_ps(t4, t6, _MM_SHUFFLE(3, 2, 3, 2));
  const __m256 s6 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(1, 0, 1, 0)), s7 = _mm256_shuffle_ps(t5, t7, _MM_SHUFFLE(3, 2, 3, 2));
  row[0] = _mm256_permute2f128_ps(s0, s4, 0x20), row[1] = _mm256_permute2f128_ps(s1, s5, 0x20);
  row[2] = _mm256_permute2f128_ps(s2, s6, 0x20), row[3] = _mm256_permute2f128_ps(s3, s7, 0x20);
  row[4] = _mm256_permute2f128_ps(s0, s4, 0x31), row[5] = _mm256_permute2f128_ps(s1, s5, 0x31);
  row[6] = _mm256_permute2f128_ps(s2, s6, 0x31), row[7] = _mm256_permute2f128_ps(s3, s7, 0x31);
}

// A packet's answers for one node, collected ray by ray (`add`) and read child by child: the
// children some ray entered, the rays that entered each, their entry distances into it, and
// the least of those (by which the packet orders its visits).
struct PacketChildren {
  __m256 near[8];  // row r: ray r's entry distances (+inf for rays not added); after turn_to_children(), row k: child k's
  __m256 least = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  std::uint64_t entered_by_ray = 0;  // byte r: the children ray r entered

  [[gnu::always_inline]] PacketChildren() {
    for (__m256& row : near) row = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  }
  [[gnu::always_inline]] void add(int ray, unsigned entered, __m256 distances) {
    near[ray] = distances;
    least = _mm256_blendv_ps(least, _mm256_min_ps(least, distances), _mm256_castsi256_ps(lane_sort::lanes_of(entered)));
    entered_by_ray |= std::uint64_t(entered) << (8 * ray);
  }
  [[gnu::always_inline]] unsigned any() const {
    std::uint64_t folded = entered_by_ray | entered_by_ray >> 32;
    folded |= folded >> 16;
    return unsigned(folded | folded >> 8) & 0xFFu;
  }
  // Byte k: the rays that entered child k.
  [[gnu::always_inline]] std::uint64_t rays_by_child() const { return transpose_bits_8x8(entered_by_ray); }
  [[gnu::always_inline]] void turn_to_children() { transpose_lanes_8x8(near); }
};
#endif

}  // namespace wavetrace
