// Keys along a Z (Morton) or a Hilbert curve through a D-dimensional grid of 2^bits cells
// per axis (D * bits <= 63): the ordering keys of ray reordering. Dimension 0 takes the
// most significant bit of each D-bit group.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
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

// Every dimension's mask, made by the compiler: made per key they cost 15 ns of a 20 ns key.
template <int D, int kBits>
inline constexpr std::array<std::uint64_t, D> kInterleaveMasks = [] {
  std::array<std::uint64_t, D> masks{};
  for (int d = 0; d < D; ++d) masks[d] = interleave_mask<D>(d, kBits);
  return masks;
}();

template <int D, int kBits>
inline std::uint64_t morton_key(const std::array<std::uint32_t, D>& cell) {
  static_assert(D * kBits <= 63, "a key holds at most 63 bits");
  std::uint64_t key = 0;
#if WAVETRACE_BMI2
  for (int d = 0; d < D; ++d) key |= _pdep_u64(cell[d], kInterleaveMasks<D, kBits>[d]);
#else
  for (int bit = kBits - 1; bit >= 0; --bit) {
    for (int d = 0; d < D; ++d) key = (key << 1) | ((cell[d] >> bit) & 1u);
  }
#endif
  return key;
}

// Skilling's transform ("Programming the Hilbert curve", 2004): the cell's coordinates
// become the transposed Hilbert index, whose interleaving is the index itself. Written
// without a branch on the coordinates' bits, so that `Coordinate` is one cell's std::uint32_t
// or a GCC vector of them, a cell in each lane: a branch a bit a dimension mispredicted half
// the time (a 6D key at 10 bits took 160 ns; 8 cells in lanes take about 22 ns each).
template <int D, int kBits, typename Coordinate>
inline void hilbert_transpose(Coordinate (&cell)[D]) {
  for (int level = kBits - 1; level > 0; --level) {  // undo excess work: inverse and exchange
    const std::uint32_t low = (std::uint32_t{1} << level) - 1;
    cell[0] ^= low & (0u - ((cell[0] >> level) & 1u));  // dimension 0: an inverse or nothing
    for (int d = 1; d < D; ++d) {
      const Coordinate set = 0u - ((cell[d] >> level) & 1u);  // all ones where the bit is set
      const Coordinate swap = (cell[0] ^ cell[d]) & low & ~set;
      cell[0] ^= (low & set) | swap;  // set: invert dimension 0's low bits; clear: exchange them
      cell[d] ^= swap;
    }
  }
  for (int d = 1; d < D; ++d) cell[d] ^= cell[d - 1];  // Gray encode
  Coordinate flip = cell[D - 1] & 0u;  // zero, of the coordinates' type
  for (int level = kBits - 1; level > 0; --level) {
    flip ^= ((std::uint32_t{1} << level) - 1) & (0u - ((cell[D - 1] >> level) & 1u));
  }
  for (int d = 0; d < D; ++d) cell[d] ^= flip;
}

template <int D, int kBits>
inline std::uint64_t hilbert_key(const std::array<std::uint32_t, D>& cell) {
  static_assert(D * kBits <= 63, "a key holds at most 63 bits");
  std::uint32_t transposed[D];
  for (int d = 0; d < D; ++d) transposed[d] = cell[d];
  hilbert_transpose<D, kBits>(transposed);
  std::array<std::uint32_t, D> index;
  for (int d = 0; d < D; ++d) index[d] = transposed[d];
  return morton_key<D, kBits>(index);
}

// Hilbert keys of kHilbertLanes cells at once: cells[d][lane] is coordinate d of a lane's cell.
inline constexpr std::size_t kHilbertLanes = 8;
using HilbertLanes = std::uint32_t __attribute__((vector_size(kHilbertLanes * sizeof(std::uint32_t))));

template <int D, int kBits>
inline void hilbert_keys(const std::uint32_t (&cells)[D][kHilbertLanes], std::uint64_t (&keys)[kHilbertLanes]) {
  static_assert(D * kBits <= 63, "a key holds at most 63 bits");
  HilbertLanes transposed[D];
  for (int d = 0; d < D; ++d) std::memcpy(&transposed[d], cells[d], sizeof(HilbertLanes));
  hilbert_transpose<D, kBits>(transposed);
  for (std::size_t lane = 0; lane < kHilbertLanes; ++lane) {
    std::array<std::uint32_t, D> index;
    for (int d = 0; d < D; ++d) index[d] = transposed[d][lane];
    keys[lane] = morton_key<D, kBits>(index);
  }
}

}  // namespace wavetrace
