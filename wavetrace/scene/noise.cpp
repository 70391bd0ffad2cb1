// Gradient noise with hashed lattice gradients and a quintic fade.
#include "wavetrace/scene/noise.hpp"

#include <cmath>

#include "wavetrace/kernels/random.hpp"

namespace wavetrace {
namespace {

float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

// One of the 12 cube-edge directions, as in improved Perlin noise, by table: a switch on the
// hash mispredicted about half its jumps and made the noise a quarter of a room's build. A
// component of 0 adds a signed zero, which changes no sum of the fractal (it starts at +0).
struct EdgeGradient {
  float x, y, z;
};
constexpr EdgeGradient kEdgeGradients[12] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                             {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};

const EdgeGradient& lattice_gradient(int x, int y, int z, std::uint32_t seed) {
  const std::uint64_t key = (std::uint64_t(std::uint32_t(x)) * 0x9E3779B1u) ^
                            (std::uint64_t(std::uint32_t(y)) << 21) ^ (std::uint64_t(std::uint32_t(z)) << 42) ^
                            (std::uint64_t(seed) << 13);
  return kEdgeGradients[mix64(key) % 12];
}

float dot(const EdgeGradient& g, const glm::vec3& offset) { return g.x * offset.x + g.y * offset.y + g.z * offset.z; }

// The gradients of the cell a thread last visited, a slot per seed (a fractal's octaves have
// seeds 101 apart, odd, so up to sixteen octaves take sixteen different slots). Shapes generate their vertices
// in lattice order, and a fine vertex lattice visits a noise cell many times in a row, so
// most calls skip the eight hashes; the gradients, and so the values, are the same.
struct CellGradients {
  int x = 0, y = 0, z = 0;
  std::uint32_t seed = 0;
  bool valid = false;
  const EdgeGradient* corner[8];
};
constexpr std::uint32_t kCellCacheSlots = 16;
thread_local CellGradients cell_cache[kCellCacheSlots];

const CellGradients& cell_gradients(int x, int y, int z, std::uint32_t seed) {
  CellGradients& cell = cell_cache[seed % kCellCacheSlots];
  if (cell.valid && cell.x == x && cell.y == y && cell.z == z && cell.seed == seed) return cell;
  for (int c = 0; c < 8; ++c) cell.corner[c] = &lattice_gradient(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1), seed);
  cell.x = x, cell.y = y, cell.z = z, cell.seed = seed, cell.valid = true;
  return cell;
}

float lerp(float a, float b, float t) { return a + (b - a) * t; }

}  // namespace

float gradient_noise(const glm::vec3& point, std::uint32_t seed) {
  const glm::vec3 cell(std::floor(point.x), std::floor(point.y), std::floor(point.z));
  const int x = static_cast<int>(cell.x), y = static_cast<int>(cell.y), z = static_cast<int>(cell.z);
  const glm::vec3 f = point - cell;
  const float u = fade(f.x), v = fade(f.y), w = fade(f.z);
  const CellGradients& gradients = cell_gradients(x, y, z, seed);
  float corners[8];
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    corners[c] = dot(*gradients.corner[c], f - glm::vec3(float(dx), float(dy), float(dz)));
  }
  const float x00 = lerp(corners[0], corners[1], u), x10 = lerp(corners[2], corners[3], u);
  const float x01 = lerp(corners[4], corners[5], u), x11 = lerp(corners[6], corners[7], u);
  return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

float fractal_noise(const glm::vec3& point, int octaves, std::uint32_t seed) {
  float sum = 0.0f, amplitude = 0.5f, frequency = 1.0f;
  for (int octave = 0; octave < octaves; ++octave) {
    sum += amplitude * gradient_noise(point * frequency, seed + 101u * octave);
    amplitude *= 0.5f;
    frequency *= 2.0f;
  }
  return sum;
}

}  // namespace wavetrace
