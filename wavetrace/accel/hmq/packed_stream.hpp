// Bit strings: values of `bits` bits laid end to end from a bit position of a byte array, the
// array read as one little-endian number, so that value i of a stream starting at bit s holds
// bits s + i·bits .. s + (i + 1)·bits - 1. Each value is read with one unaligned load at its
// first byte: 8 bytes for up to 32 bits, 4 for up to 25 (the lanes' gathers). An array holding
// streams keeps 8 bytes of slack after its last value for those loads.
//
// HMQ's Appendix A packs floor(64 / bits) values to a quad-word and starts the next group, and
// every stream, at a byte, so that no value straddles two quad-words of an aligned load. An
// unaligned load at a value's first byte never straddles either, so nothing needs the groups,
// and streams laid end to end save their tails: a quarter of a byte a triangle on the scans.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "wavetrace/memory/cache_aligned_allocator.hpp"

#if WAVETRACE_AVX2
#include <immintrin.h>
#endif

namespace wavetrace::hmq {

// Bits a stream of `count` values of `bits` bits takes.
constexpr std::size_t stream_bits(std::uint32_t bits, std::uint32_t count) { return std::size_t(bits) * count; }

// i · bits for every width 1 .. 32 and i < 16, as 16-bit lanes: the lane readers' offsets
// from their first value, loaded rather than multiplied.
inline constexpr auto kStreamBitOffsets = [] {
  std::array<std::array<std::uint16_t, 16>, 33> offsets{};
  for (std::uint32_t bits = 1; bits <= 32; ++bits) {
    for (std::uint32_t i = 0; i < 16; ++i) offsets[bits][i] = static_cast<std::uint16_t>(i * bits);
  }
  return offsets;
}();

// The value of `bits` (0 .. 32) bits at bit `bit` of `data`.
inline std::uint32_t read_value(const std::byte* data, std::size_t bit, std::uint32_t bits) {
  std::uint64_t word;
  std::memcpy(&word, data + bit / 8, 8);  // unaligned
  return static_cast<std::uint32_t>((word >> (bit % 8)) & ((std::uint64_t{1} << bits) - 1));
}

// Decodes `count` values of `bits` bits, the first at bit `first_bit` of `data`, into `out`.
inline void read_stream(const std::byte* data, std::size_t first_bit, std::uint32_t bits, std::uint32_t count,
                        std::uint32_t* out) {
  for (std::uint32_t i = 0; i < count; ++i) out[i] = read_value(data, first_bit + std::size_t(i) * bits, bits);
}

// Appends values to a byte array as one bit string; finish() pads the last byte with zeros.
class BitWriter {
 public:
  explicit BitWriter(LargeArray<std::byte>& out) : out_(out) {}

  // `value` must fit in `bits` (0 .. 32) bits.
  void append(std::uint32_t value, std::uint32_t bits) {
    pending_ |= std::uint64_t(value) << pending_bits_;
    pending_bits_ += bits;
    written_bits_ += bits;
    for (; pending_bits_ >= 8; pending_bits_ -= 8, pending_ >>= 8) out_.push_back(static_cast<std::byte>(pending_));
  }
  void append_stream(std::span<const std::uint32_t> values, std::uint32_t bits) {
    for (const std::uint32_t value : values) append(value, bits);
  }
  std::size_t written_bits() const { return written_bits_; }
  void finish() {
    if (pending_bits_ > 0) out_.push_back(static_cast<std::byte>(pending_));
    pending_ = 0;
    pending_bits_ = 0;
  }

 private:
  LargeArray<std::byte>& out_;
  std::uint64_t pending_ = 0;
  std::uint32_t pending_bits_ = 0;
  std::size_t written_bits_ = 0;
};

// The widest values the lane readers take: a value and its bit offset within its first byte
// fit one 4-byte load.
inline constexpr std::uint32_t kLaneStreamBits = 25;

#if WAVETRACE_AVX2
// Values first .. first + 7 of a stream of `bits` (1 .. kLaneStreamBits) bits
// starting at bit `first_bit` of `data`, in eight lanes; lanes at or past `count` hold 0. No
// gather: the eight values span at most 7 four-byte words from the first one's byte, so one
// masked load takes them (its last word reaches at most 3 bytes past the last value, within an
// array's slack), and each lane picks the word its value starts in and the next by permutes,
// and shifts the value out of the pair.
[[gnu::always_inline]] inline __m256i read_stream_lanes(const std::byte* data, std::uint32_t first_bit,
                                                        std::uint32_t bits, std::uint32_t first, std::uint32_t count) {
  const std::uint32_t start = first_bit + first * bits;
  const std::uint32_t values = count - first >= 8 ? 8u : count - first;
  const std::uint32_t lead = start % 8;
  const std::uint32_t words = (lead + values * bits + 31) / 32;
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i window = _mm256_maskload_epi32(reinterpret_cast<const int*>(data + start / 8),
                                               _mm256_cmpgt_epi32(_mm256_set1_epi32(int(words)), lane));
  const __m256i offset = _mm256_add_epi32(  // from the window's first bit
      _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(kStreamBitOffsets[bits].data()))),
      _mm256_set1_epi32(int(lead)));
  const __m256i word = _mm256_srli_epi32(offset, 5), shift = _mm256_and_si256(offset, _mm256_set1_epi32(31));
  const __m256i low = _mm256_permutevar8x32_epi32(window, word);
  const __m256i high = _mm256_permutevar8x32_epi32(window, _mm256_add_epi32(word, _mm256_set1_epi32(1)));
  // A shift by 32 (a value that starts its word) gives 0, as the next word's part must be.
  const __m256i value = _mm256_or_si256(_mm256_srlv_epi32(low, shift),
                                        _mm256_sllv_epi32(high, _mm256_sub_epi32(_mm256_set1_epi32(32), shift)));
  const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32(int(values)), lane);
  return _mm256_and_si256(_mm256_and_si256(value, live), _mm256_set1_epi32(int((std::uint32_t{1} << bits) - 1)));
}
#endif

#if WAVETRACE_AVX512_DISPATCH
// Sixteen 32-bit lanes as GCC's vector extension: in a function of the AVX-512 target its
// operators compile to ZMM instructions, without the intrinsics' _mm512_undefined inputs that
// GCC 12 reports as maybe uninitialized once inlined.
using SixteenU32 = std::uint32_t __attribute__((vector_size(64)));
using SixteenU16 = std::uint16_t __attribute__((vector_size(32)));

// read_stream_lanes in sixteen lanes, for the AVX-512 walks (a function of that target),
// without a gather: the sixteen values span at most 51 bytes from the first one's byte, so
// one load masked to those bytes takes them all (nothing past the last value is read), and
// each lane picks the 4-byte word its value starts in and the next by permutes, and shifts
// the value out of the pair.
[[WAVETRACE_AVX512_TARGET]] inline SixteenU32 read_stream_sixteen(const std::byte* data, std::uint32_t first_bit,
                                                                  std::uint32_t bits, std::uint32_t first,
                                                                  std::uint32_t count) {
  const std::uint32_t start = first_bit + first * bits;
  const std::uint32_t values = count - first >= 16 ? 16u : count - first;
  const __mmask16 live = static_cast<__mmask16>((1u << values) - 1u);
  const std::uint32_t lead = start % 8;
  const std::uint32_t bytes = (lead + values * bits + 7) / 8;  // at most 51
  const __m512i window = _mm512_maskz_loadu_epi8((std::uint64_t{1} << bytes) - 1u, data + start / 8);
  SixteenU16 offset16;
  std::memcpy(&offset16, kStreamBitOffsets[bits].data(), sizeof(offset16));
  const SixteenU32 offset = __builtin_convertvector(offset16, SixteenU32) + lead;  // from the window's first bit
  const SixteenU32 shift = offset & 31u;
  const __m512i low = _mm512_maskz_permutexvar_epi32(live, __m512i(offset >> 5u), window);
  const __m512i high = _mm512_maskz_permutexvar_epi32(live, __m512i((offset >> 5u) + 1u), window);
  // A shift by 32 (a value that starts its word) gives 0, as the next word's part must be.
  const SixteenU32 value = SixteenU32(_mm512_maskz_srlv_epi32(live, low, __m512i(shift))) |
                           SixteenU32(_mm512_maskz_sllv_epi32(live, high, __m512i(32u - shift)));
  return value & ((std::uint32_t{1} << bits) - 1u);
}
#endif

}  // namespace wavetrace::hmq
