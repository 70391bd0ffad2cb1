// Deterministic 3D gradient noise and its fractal sum, for procedural displacement.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

namespace wavetrace {

// Perlin-style gradient noise in about [-1, 1]; a pure function of the point and seed.
float gradient_noise(const glm::vec3& point, std::uint32_t seed);

// Fractional Brownian motion: octaves of gradient noise, each twice the frequency and
// half the amplitude of the last; roughly in [-1, 1].
float fractal_noise(const glm::vec3& point, int octaves, std::uint32_t seed);
// The same sum an octave at a time, as fractal_noise computes it in SIMD lanes for up to eight
// octaves (to the bit: tested).
float fractal_noise_scalar(const glm::vec3& point, int octaves, std::uint32_t seed);

}  // namespace wavetrace
