// Bit strings laid out for fast decoding (HMQ Appendix A): values of `bits` bits are packed
// p = floor(64 / bits) to a 64-bit little-endian quad-word, and the next group starts at the
// next *byte* after them, so every group is read with one unaligned 8-byte load and shifts,
// never a value straddling two words. A stream of `count` values takes
// (count / p) * ceil(p * bits / 8) + ceil((count % p) * bits / 8) bytes; decoding may read up
// to 8 bytes from a group's start, so the buffer holding streams keeps 8 bytes of slack.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "wavetrace/memory/cache_aligned_allocator.hpp"

#if WAVETRACE_AVX2
#include <immintrin.h>
#endif

namespace wavetrace::hmq {

struct StreamShape {
  std::uint32_t per_group;    // values per quad-word
  std::uint32_t group_bytes;  // bytes from one group's start to the next
};

constexpr StreamShape compute_stream_shape(std::uint32_t bits) {
  const std::uint32_t per_group = bits == 0 ? 64 : 64 / bits;
  return {per_group, (per_group * bits + 7) / 8};
}

// Appendix A's look-up table: the shape for every width 0 .. 64, so decoding divides nothing.
inline constexpr auto kStreamShapes = [] {
  std::array<StreamShape, 65> shapes{};
  for (std::uint32_t bits = 0; bits <= 64; ++bits) shapes[bits] = compute_stream_shape(bits);
  return shapes;
}();

constexpr StreamShape stream_shape(std::uint32_t bits) { return kStreamShapes[bits]; }

// Where value i (< 64) of a stream of `bits` (1 .. 32) bits starts, in bits from the stream's
// start: the group's start, (i / per_group) * group_bytes bytes in, and (i % per_group) * bits.
inline constexpr auto kStreamBitOffsets = [] {
  std::array<std::array<std::uint16_t, 64>, 33> offsets{};
  for (std::uint32_t bits = 1; bits <= 32; ++bits) {
    const StreamShape shape = compute_stream_shape(bits);
    for (std::uint32_t i = 0; i < 64; ++i) {
      offsets[bits][i] = static_cast<std::uint16_t>(i / shape.per_group * shape.group_bytes * 8 + i % shape.per_group * bits);
    }
  }
  return offsets;
}();

// Bytes a stream of `count` values takes. Up to 64 values (every stream of a leaf record) from
// where its last value ends: a decoder steps from stream to stream by it, and the division
// by per_group the general formula needs would sit in that chain once a stream.
constexpr std::size_t stream_bytes(std::uint32_t bits, std::uint32_t count) {
  if (bits == 0 || count == 0) return 0;
  if (count <= 64 && bits <= 32) return (std::size_t(kStreamBitOffsets[bits][count - 1]) + bits + 7) / 8;
  const StreamShape shape = stream_shape(bits);
  return std::size_t(count / shape.per_group) * shape.group_bytes + ((count % shape.per_group) * bits + 7) / 8;
}

// The widest values read_stream_lanes takes: a value and its bit offset within its first byte
// fit one 4-byte load.
inline constexpr std::uint32_t kLaneStreamBits = 25;

#if WAVETRACE_AVX2
// Values first .. first + 7 of a stream of `bits` (1 .. kLaneStreamBits) bits in eight lanes,
// each from one 4-byte load at its first byte; lanes at or past `count` read nothing and hold
// 0. A value's load ends at most 3 bytes past its stream, within a record's 8 bytes of slack.
[[gnu::always_inline]] inline __m256i read_stream_lanes(const std::byte* data, std::uint32_t bits, std::uint32_t first,
                                                        std::uint32_t count) {
  const __m256i offset = _mm256_cvtepu16_epi32(
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(kStreamBitOffsets[bits].data() + first)));
  const __m256i index = _mm256_add_epi32(_mm256_set1_epi32(int(first)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count)), index);
  const __m256i word = _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(data),
                                                   _mm256_srli_epi32(offset, 3), live, 1);
  const __m256i value = _mm256_srlv_epi32(word, _mm256_and_si256(offset, _mm256_set1_epi32(7)));
  return _mm256_and_si256(value, _mm256_set1_epi32(int((std::uint32_t{1} << bits) - 1)));
}
#endif

#if WAVETRACE_AVX512_DISPATCH
// Sixteen 32-bit lanes as GCC's vector extension: in a function of the AVX-512 target its
// operators compile to ZMM instructions, without the intrinsics' _mm512_undefined inputs that
// GCC 12 reports as maybe uninitialized once inlined.
using SixteenU32 = std::uint32_t __attribute__((vector_size(64)));
using SixteenU16 = std::uint16_t __attribute__((vector_size(32)));

// read_stream_lanes in sixteen lanes, for the AVX-512 walks (a function of that target).
[[WAVETRACE_AVX512_TARGET]] inline SixteenU32 read_stream_sixteen(const std::byte* data, std::uint32_t bits,
                                                                  std::uint32_t first, std::uint32_t count) {
  SixteenU16 offset16;
  std::memcpy(&offset16, kStreamBitOffsets[bits].data() + first, sizeof(offset16));
  const SixteenU32 offset = __builtin_convertvector(offset16, SixteenU32);
  const __mmask16 live = static_cast<__mmask16>(count - first >= 16 ? 0xffffu : (1u << (count - first)) - 1u);
  const SixteenU32 word = SixteenU32(
      _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), live, __m512i(offset >> 3u), data, 1));
  return (word >> (offset & 7u)) & ((std::uint32_t{1} << bits) - 1u);
}
#endif

// Appends the stream to `out`; every value must fit in `bits` (0 .. 32) bits.
inline void append_stream(LargeArray<std::byte>& out, std::span<const std::uint32_t> values, std::uint32_t bits) {
  if (bits == 0) return;
  const StreamShape shape = stream_shape(bits);
  for (std::size_t first = 0; first < values.size(); first += shape.per_group) {
    std::uint64_t word = 0;
    const std::size_t count = std::min<std::size_t>(shape.per_group, values.size() - first);
    for (std::size_t j = 0; j < count; ++j) word |= std::uint64_t(values[first + j]) << (j * bits);
    const std::size_t bytes = (count * bits + 7) / 8;
    for (std::size_t b = 0; b < bytes; ++b) out.push_back(static_cast<std::byte>(word >> (8 * b)));
  }
}

// Decodes `count` values of `bits` bits from `data` into `out`.
inline void read_stream(const std::byte* data, std::uint32_t bits, std::uint32_t count, std::uint32_t* out) {
  if (bits == 0) {
    for (std::uint32_t i = 0; i < count; ++i) out[i] = 0;
    return;
  }
  const StreamShape shape = stream_shape(bits);
  const std::uint64_t mask = (std::uint64_t{1} << bits) - 1;
  for (std::uint32_t first = 0; first < count; first += shape.per_group, data += shape.group_bytes) {
    std::uint64_t word;
    std::memcpy(&word, data, 8);  // unaligned
    const std::uint32_t end = std::min(count - first, shape.per_group);
    for (std::uint32_t j = 0; j < end; ++j) out[first + j] = static_cast<std::uint32_t>((word >> (j * bits)) & mask);
  }
}

}  // namespace wavetrace::hmq
