// Gradient noise with hashed lattice gradients and a quintic fade.
#include "wavetrace/scene/noise.hpp"

#include <bit>
#include <cmath>

#include <immintrin.h>

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

namespace {

// The octaves of one fractal sum side by side, an octave a lane (AVX2, which the build's
// x86-64-v3 has): each lane does the scalar gradient_noise's operations in its order, without
// contraction (-ffp-contract=off), so the sum is the scalar one to the bit. The octaves, each
// a dependent chain of lerps, were a sixth of a room's chunked build (generated twice: the
// bounds pass, then each chunk).
constexpr int kOctaveLanes = 8;

// The last lattice cell of every octave, and the gradient indices of its eight corners, for
// one seed and octave count (a thread generates one shape at a time, in lattice order); lanes
// past the count are never read.
struct OctaveCells {
  std::uint32_t seed = 0;
  int octaves = 0;  // 0: nothing cached
  alignas(32) std::int32_t x[kOctaveLanes], y[kOctaveLanes], z[kOctaveLanes];
  alignas(32) std::int32_t gradient[8][kOctaveLanes];  // [corner][octave] -> index into kEdgeGradients
};
thread_local OctaveCells octave_cells;

std::int32_t gradient_index(int x, int y, int z, std::uint32_t seed) {
  return static_cast<std::int32_t>(&lattice_gradient(x, y, z, seed) - kEdgeGradients);
}

// A gradient component by index (0..11) from two registers of the table's column.
__m256 gradient_component(__m256i index, __m256 first_eight, __m256 last_four) {
  const __m256 low = _mm256_permutevar8x32_ps(first_eight, index);
  const __m256 high = _mm256_permutevar8x32_ps(last_four, _mm256_sub_epi32(index, _mm256_set1_epi32(8)));
  return _mm256_blendv_ps(low, high, _mm256_castsi256_ps(_mm256_cmpgt_epi32(index, _mm256_set1_epi32(7))));
}

__m256 fade_lanes(__m256 t) {
  const __m256 inner = _mm256_add_ps(
      _mm256_mul_ps(t, _mm256_sub_ps(_mm256_mul_ps(t, _mm256_set1_ps(6.0f)), _mm256_set1_ps(15.0f))), _mm256_set1_ps(10.0f));
  return _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(t, t), t), inner);
}

__m256 lerp_lanes(__m256 a, __m256 b, __m256 t) { return _mm256_add_ps(a, _mm256_mul_ps(_mm256_sub_ps(b, a), t)); }

float fractal_noise_lanes(const glm::vec3& point, int octaves, std::uint32_t seed) {
  const __m256 frequency = _mm256_setr_ps(1.0f, 2.0f, 4.0f, 8.0f, 16.0f, 32.0f, 64.0f, 128.0f);
  const __m256 px = _mm256_mul_ps(_mm256_set1_ps(point.x), frequency);
  const __m256 py = _mm256_mul_ps(_mm256_set1_ps(point.y), frequency);
  const __m256 pz = _mm256_mul_ps(_mm256_set1_ps(point.z), frequency);
  const __m256 cell_x = _mm256_floor_ps(px), cell_y = _mm256_floor_ps(py), cell_z = _mm256_floor_ps(pz);
  const __m256i ix = _mm256_cvttps_epi32(cell_x), iy = _mm256_cvttps_epi32(cell_y), iz = _mm256_cvttps_epi32(cell_z);
  const __m256 fx = _mm256_sub_ps(px, cell_x), fy = _mm256_sub_ps(py, cell_y), fz = _mm256_sub_ps(pz, cell_z);

  OctaveCells& cells = octave_cells;
  const __m256i same = _mm256_and_si256(
      _mm256_cmpeq_epi32(ix, _mm256_load_si256(reinterpret_cast<const __m256i*>(cells.x))),
      _mm256_and_si256(_mm256_cmpeq_epi32(iy, _mm256_load_si256(reinterpret_cast<const __m256i*>(cells.y))),
                       _mm256_cmpeq_epi32(iz, _mm256_load_si256(reinterpret_cast<const __m256i*>(cells.z)))));
  unsigned stale = ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(same))) & ((1u << octaves) - 1u);
  if (cells.seed != seed || cells.octaves != octaves) stale = (1u << octaves) - 1u;
  if (stale != 0) {
    alignas(32) std::int32_t x[kOctaveLanes], y[kOctaveLanes], z[kOctaveLanes];
    _mm256_store_si256(reinterpret_cast<__m256i*>(x), ix);
    _mm256_store_si256(reinterpret_cast<__m256i*>(y), iy);
    _mm256_store_si256(reinterpret_cast<__m256i*>(z), iz);
    for (; stale != 0; stale &= stale - 1) {
      const int octave = std::countr_zero(stale);
      const std::uint32_t octave_seed = seed + 101u * std::uint32_t(octave);
      for (int c = 0; c < 8; ++c) {
        cells.gradient[c][octave] =
            gradient_index(x[octave] + (c & 1), y[octave] + ((c >> 1) & 1), z[octave] + ((c >> 2) & 1), octave_seed);
      }
      cells.x[octave] = x[octave], cells.y[octave] = y[octave], cells.z[octave] = z[octave];
    }
    cells.seed = seed;
    cells.octaves = octaves;
  }

  const __m256 u = fade_lanes(fx), v = fade_lanes(fy), w = fade_lanes(fz);
  const __m256 table_x0 = _mm256_setr_ps(1, -1, 1, -1, 1, -1, 1, -1), table_x1 = _mm256_setr_ps(0, 0, 0, 0, 0, 0, 0, 0);
  const __m256 table_y0 = _mm256_setr_ps(1, 1, -1, -1, 0, 0, 0, 0), table_y1 = _mm256_setr_ps(1, -1, 1, -1, 0, 0, 0, 0);
  const __m256 table_z0 = _mm256_setr_ps(0, 0, 0, 0, 1, 1, -1, -1), table_z1 = _mm256_setr_ps(1, 1, -1, -1, 0, 0, 0, 0);
  const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps();
  __m256 corners[8];
  for (int c = 0; c < 8; ++c) {
    const __m256i index = _mm256_load_si256(reinterpret_cast<const __m256i*>(cells.gradient[c]));
    const __m256 gx = gradient_component(index, table_x0, table_x1);
    const __m256 gy = gradient_component(index, table_y0, table_y1);
    const __m256 gz = gradient_component(index, table_z0, table_z1);
    const __m256 ox = _mm256_sub_ps(fx, (c & 1) ? one : zero);
    const __m256 oy = _mm256_sub_ps(fy, ((c >> 1) & 1) ? one : zero);
    const __m256 oz = _mm256_sub_ps(fz, ((c >> 2) & 1) ? one : zero);
    corners[c] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(gx, ox), _mm256_mul_ps(gy, oy)), _mm256_mul_ps(gz, oz));
  }
  const __m256 x00 = lerp_lanes(corners[0], corners[1], u), x10 = lerp_lanes(corners[2], corners[3], u);
  const __m256 x01 = lerp_lanes(corners[4], corners[5], u), x11 = lerp_lanes(corners[6], corners[7], u);
  alignas(32) float noise[kOctaveLanes];
  _mm256_store_ps(noise, lerp_lanes(lerp_lanes(x00, x10, v), lerp_lanes(x01, x11, v), w));

  float sum = 0.0f, amplitude = 0.5f;
  for (int octave = 0; octave < octaves; ++octave) {
    sum += amplitude * noise[octave];
    amplitude *= 0.5f;
  }
  return sum;
}

}  // namespace

float fractal_noise(const glm::vec3& point, int octaves, std::uint32_t seed) {
  if (octaves >= 1 && octaves <= kOctaveLanes) return fractal_noise_lanes(point, octaves, seed);
  return fractal_noise_scalar(point, octaves, seed);
}

float fractal_noise_scalar(const glm::vec3& point, int octaves, std::uint32_t seed) {
  float sum = 0.0f, amplitude = 0.5f, frequency = 1.0f;
  for (int octave = 0; octave < octaves; ++octave) {
    sum += amplitude * gradient_noise(point * frequency, seed + 101u * octave);
    amplitude *= 0.5f;
    frequency *= 2.0f;
  }
  return sum;
}

}  // namespace wavetrace
