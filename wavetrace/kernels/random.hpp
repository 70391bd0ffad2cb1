// Counter-based randomness: every random number is a pure function of
// (pixel, sample, depth, purpose, dimension), never of the thread or the ray order,
// so an image is bit-identical for any thread count, batch size or reorder heuristic.
#pragma once

#include <cstdint>

namespace wavetrace {

// Why a random number is drawn; distinct purposes give independent streams.
enum class RandomPurpose : std::uint32_t {
  pixel_jitter = 1,
  light_choice = 2,
  light_point = 3,
  bounce_direction = 4,
  russian_roulette = 5,
  scene_generation = 6,
  benchmark = 7,
  simplification = 8,
  fresnel_choice = 9,
  photon_emission = 10,
  gather_direction = 11,
  gather_key = 12,
  chunk_probe = 13,
};

// A 64-bit finalizer (SplitMix64's): full avalanche, cheap, and good enough for sampling.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}

// The path tracer's draws. Every draw of one path starts from its (pixel, sample) key,
// 64 bits so that no two paths of an image share one; a stage hashes the pair once per ray
// (path_key) and finishes each draw in 32-bit lanes (path_draw), which AVX2 multiplies
// eight at a time, where it has no 64-bit multiply: the stages' loops over rays vectorize.
constexpr std::uint64_t path_key(std::uint32_t pixel, std::uint32_t sample) {
  return mix64((std::uint64_t{pixel} << 32) | sample);
}

// A 32-bit finalizer (Wellons' lowbias32: two multiply-xorshift rounds, bias ~0.17).
constexpr std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// 32 random bits of a path at a depth, for one purpose and dimension (depth < 2^16,
// dimension < 2^8): the high half of the key, tagged, hashed, then the low half, hashed.
// Loops keep the key's halves in two 32-bit columns, which vectorize where 64-bit ones do not.
constexpr std::uint32_t path_draw(std::uint32_t key_high, std::uint32_t key_low, std::uint32_t depth,
                                  RandomPurpose purpose, std::uint32_t dimension = 0) {
  const std::uint32_t tag = (depth << 16) ^ (std::uint32_t(purpose) << 8) ^ dimension;
  return hash32(key_low ^ hash32(key_high ^ (tag * 0x9e3779b9u)));
}
constexpr std::uint32_t path_draw(std::uint64_t path, std::uint32_t depth, RandomPurpose purpose,
                                  std::uint32_t dimension = 0) {
  return path_draw(std::uint32_t(path >> 32), std::uint32_t(path), depth, purpose, dimension);
}

// Uniform float in [0, 1) from a draw's top 24 bits.
constexpr float unit_float32(std::uint32_t bits) {
  return static_cast<float>(static_cast<std::int32_t>(bits >> 8)) * (1.0f / 16777216.0f);
}

// 64 random bits for everything else (scenes, proxies, benchmark rays), from the same keys.
constexpr std::uint64_t random_bits(std::uint32_t pixel, std::uint32_t sample, std::uint32_t depth,
                                    RandomPurpose purpose, std::uint32_t dimension = 0) {
  std::uint64_t key = mix64((std::uint64_t{pixel} << 32) | sample);
  return mix64(key ^ ((std::uint64_t{depth} << 40) | (std::uint64_t(purpose) << 24) | dimension));
}

// Uniform float in [0, 1) from the top 24 bits.
// (Through a 32-bit int: a 64-bit integer to float conversion does not vectorize on AVX2.)
constexpr float unit_float(std::uint64_t bits) {
  return static_cast<float>(static_cast<std::int32_t>(bits >> 40)) * (1.0f / 16777216.0f);
}

// Two independent uniform floats in [0, 1) from one 64-bit draw.
struct UnitPair {
  float first;
  float second;
};
constexpr UnitPair unit_pair(std::uint64_t bits) {
  return {static_cast<float>(static_cast<std::int32_t>(bits >> 40)) * (1.0f / 16777216.0f),
          static_cast<float>(static_cast<std::int32_t>((bits >> 8) & 0xFFFFFFu)) * (1.0f / 16777216.0f)};
}

}  // namespace wavetrace
