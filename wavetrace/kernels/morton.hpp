// Morton (Z-order) codes: bit interleaving with BMI2 where the compiler has it.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2

#include <cstdint>
#if WAVETRACE_BMI2
#include <immintrin.h>
#endif

namespace wavetrace {

constexpr std::uint64_t kMortonMask2dX = 0x5555555555555555ull;
constexpr std::uint64_t kMortonMask2dY = 0xAAAAAAAAAAAAAAAAull;

inline std::uint64_t morton2d_encode(std::uint32_t x, std::uint32_t y) {
#if WAVETRACE_BMI2
  return _pdep_u64(x, kMortonMask2dX) | _pdep_u64(y, kMortonMask2dY);
#else
  std::uint64_t code = 0;
  for (int bit = 0; bit < 32; ++bit) {
    code |= (std::uint64_t{(x >> bit) & 1u} << (2 * bit)) | (std::uint64_t{(y >> bit) & 1u} << (2 * bit + 1));
  }
  return code;
#endif
}

struct Point2u {
  std::uint32_t x, y;
};
inline Point2u morton2d_decode(std::uint64_t code) {
#if WAVETRACE_BMI2
  return {static_cast<std::uint32_t>(_pext_u64(code, kMortonMask2dX)),
          static_cast<std::uint32_t>(_pext_u64(code, kMortonMask2dY))};
#else
  Point2u point{0, 0};
  for (int bit = 0; bit < 32; ++bit) {
    point.x |= static_cast<std::uint32_t>((code >> (2 * bit)) & 1u) << bit;
    point.y |= static_cast<std::uint32_t>((code >> (2 * bit + 1)) & 1u) << bit;
  }
  return point;
#endif
}

// 3D codes: up to 21 bits per axis, x in the lowest bit of each triple.
constexpr std::uint64_t kMortonMask3dX = 0x1249249249249249ull;

inline std::uint64_t morton3d_encode(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
#if WAVETRACE_BMI2
  return _pdep_u64(x, kMortonMask3dX) | _pdep_u64(y, kMortonMask3dX << 1) | _pdep_u64(z, kMortonMask3dX << 2);
#else
  std::uint64_t code = 0;
  for (int bit = 0; bit < 21; ++bit) {
    code |= (((x >> bit) & 1u) << (3 * bit)) | (((y >> bit) & 1u) << (3 * bit + 1)) | (((z >> bit) & 1u) << (3 * bit + 2));
  }
  return code;
#endif
}

}  // namespace wavetrace
