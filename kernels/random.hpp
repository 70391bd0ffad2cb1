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

// Every draw of one path starts from its (pixel, sample) key: a stage that makes several
// draws for a ray hashes the pair once (path_key) and finishes each draw from it.
constexpr std::uint64_t path_key(std::uint32_t pixel, std::uint32_t sample) {
  return mix64((std::uint64_t{pixel} << 32) | sample);
}

constexpr std::uint64_t path_random_bits(std::uint64_t path, std::uint32_t depth, RandomPurpose purpose,
                                         std::uint32_t dimension = 0) {
  return mix64(path ^ ((std::uint64_t{depth} << 40) | (std::uint64_t(purpose) << 24) | dimension));
}

constexpr std::uint64_t random_bits(std::uint32_t pixel, std::uint32_t sample, std::uint32_t depth,
                                    RandomPurpose purpose, std::uint32_t dimension = 0) {
  return path_random_bits(path_key(pixel, sample), depth, purpose, dimension);
}

// Uniform float in [0, 1) from the top 24 bits.
constexpr float unit_float(std::uint64_t bits) {
  return static_cast<float>(bits >> 40) * (1.0f / 16777216.0f);
}

// Two independent uniform floats in [0, 1) from one 64-bit draw.
struct UnitPair {
  float first;
  float second;
};
constexpr UnitPair unit_pair(std::uint64_t bits) {
  return {static_cast<float>(bits >> 40) * (1.0f / 16777216.0f),
          static_cast<float>((bits >> 8) & 0xFFFFFFu) * (1.0f / 16777216.0f)};
}

}  // namespace wavetrace
