// Keys along a Z (Morton) or a Hilbert curve through a D-dimensional grid of 2^bits cells
// per axis (D * bits <= 63): the ordering keys of ray reordering. Dimension 0 takes the
// most significant bit of each D-bit group.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2

#include <array>
#include <cstdint>
#if WAVETRACE_BMI2
#include <immintrin.h>
#endif

namespace wavetrace {

// The bit positions of dimension d in a D-dimensional interleaving of `bits` bits.
template <int D>
constexpr std::uint64_t interleave_mask(int d, int bits) {
  std::uint64_t mask = 0;
  for (int bit = 0; bit < bits; ++bit) mask |= std::uint64_t{1} << (bit * D + (D - 1 - d));
  return mask;
}

template <int D, int kBits>
inline std::uint64_t morton_key(const std::array<std::uint32_t, D>& cell) {
  static_assert(D * kBits <= 63, "a key holds at most 63 bits");
  std::uint64_t key = 0;
#if WAVETRACE_BMI2
  for (int d = 0; d < D; ++d) key |= _pdep_u64(cell[d], interleave_mask<D>(d, kBits));
#else
  for (int bit = kBits - 1; bit >= 0; --bit) {
    for (int d = 0; d < D; ++d) key = (key << 1) | ((cell[d] >> bit) & 1u);
  }
#endif
  return key;
}

// Skilling's transform ("Programming the Hilbert curve", 2004): the cell's coordinates
// become the transposed Hilbert index, whose interleaving is the index itself.
template <int D, int kBits>
inline std::uint64_t hilbert_key(std::array<std::uint32_t, D> cell) {
  static_assert(D * kBits <= 63, "a key holds at most 63 bits");
  constexpr std::uint32_t kTop = std::uint32_t{1} << (kBits - 1);
  for (std::uint32_t q = kTop; q > 1; q >>= 1) {  // undo excess work: inverse and exchange
    const std::uint32_t low = q - 1;
    for (int d = 0; d < D; ++d) {
      if (cell[d] & q) {
        cell[0] ^= low;
      } else {
        const std::uint32_t swap = (cell[0] ^ cell[d]) & low;
        cell[0] ^= swap;
        cell[d] ^= swap;
      }
    }
  }
  for (int d = 1; d < D; ++d) cell[d] ^= cell[d - 1];  // Gray encode
  std::uint32_t flip = 0;
  for (std::uint32_t q = kTop; q > 1; q >>= 1) {
    if (cell[D - 1] & q) flip ^= q - 1;
  }
  for (int d = 0; d < D; ++d) cell[d] ^= flip;
  return morton_key<D, kBits>(cell);
}

}  // namespace wavetrace
