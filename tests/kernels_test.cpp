// Pure kernels: counter-based randomness, sample warps, Morton codes, ray origin offsets,
// the packet walks' transposes.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/checked_narrowing.hpp"
#include "wavetrace/kernels/lane_transpose.hpp"
#include "wavetrace/kernels/morton.hpp"
#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/ray_offset.hpp"
#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {
namespace {

TEST(Random, DependsOnEveryKeyPart) {
  const std::uint64_t base = random_bits(10, 2, 1, RandomPurpose::bounce_direction);
  EXPECT_EQ(base, random_bits(10, 2, 1, RandomPurpose::bounce_direction));
  std::set<std::uint64_t> distinct = {base,
                                      random_bits(11, 2, 1, RandomPurpose::bounce_direction),
                                      random_bits(10, 3, 1, RandomPurpose::bounce_direction),
                                      random_bits(10, 2, 2, RandomPurpose::bounce_direction),
                                      random_bits(10, 2, 1, RandomPurpose::light_choice),
                                      random_bits(10, 2, 1, RandomPurpose::bounce_direction, 1)};
  EXPECT_EQ(distinct.size(), 6u);
}

TEST(Random, UnitFloatsAreInRangeAndRoughlyUniform) {
  double sum = 0.0;
  for (std::uint32_t i = 0; i < 100000; ++i) {
    const UnitPair pair = unit_pair(random_bits(i, 0, 0, RandomPurpose::benchmark));
    ASSERT_GE(pair.first, 0.0f);
    ASSERT_LT(pair.first, 1.0f);
    ASSERT_GE(pair.second, 0.0f);
    ASSERT_LT(pair.second, 1.0f);
    sum += pair.first + pair.second;
  }
  EXPECT_NEAR(sum / 200000.0, 0.5, 0.005);
}

TEST(Sampling, CosineHemisphereStaysAboveTheNormalWithMeanCosineTwoThirds) {
  const glm::vec3 normal = glm::normalize(glm::vec3(0.3f, -0.8f, 0.5f));
  double mean_cosine = 0.0;
  const int count = 100000;
  for (int i = 0; i < count; ++i) {
    const UnitPair u = unit_pair(random_bits(i, 0, 0, RandomPurpose::benchmark));
    const glm::vec3 direction = cosine_hemisphere(normal, u.first, u.second);
    ASSERT_NEAR(glm::length(direction), 1.0f, 1e-5f);
    ASSERT_GE(glm::dot(direction, normal), -1e-6f);
    mean_cosine += glm::dot(direction, normal);
  }
  EXPECT_NEAR(mean_cosine / count, 2.0 / 3.0, 0.005);  // E[cos] under pdf cos/pi
}

TEST(Sampling, SinCosOfTurnsMatchesLibmToAFewUlps) {
  float worst = 0.0f;
  for (int i = 0; i <= 1 << 20; ++i) {
    const float turns = float(i) / float(1 << 20);
    const SinCos value = sin_cos_turns(turns);
    const double angle = 2.0 * 3.14159265358979323846 * double(turns);
    worst = std::max({worst, float(std::fabs(value.sin - std::sin(angle))), float(std::fabs(value.cos - std::cos(angle)))});
  }
  EXPECT_LT(worst, 3e-7f);
  EXPECT_EQ(sin_cos_turns(0.0f).cos, 1.0f);
  EXPECT_EQ(sin_cos_turns(0.25f).sin, 1.0f);
  EXPECT_EQ(sin_cos_turns(0.5f).cos, -1.0f);
}

TEST(Random, PathDrawsDependOnEveryKeyPartAndAreUniform) {
  const std::uint64_t path = path_key(10, 2);
  EXPECT_EQ(path, path_key(10, 2));
  const std::uint32_t base = path_draw(path, 1, RandomPurpose::bounce_direction);
  const std::set<std::uint32_t> distinct = {base,
                                            path_draw(path_key(11, 2), 1, RandomPurpose::bounce_direction),
                                            path_draw(path_key(10, 3), 1, RandomPurpose::bounce_direction),
                                            path_draw(path, 2, RandomPurpose::bounce_direction),
                                            path_draw(path, 1, RandomPurpose::light_choice),
                                            path_draw(path, 1, RandomPurpose::bounce_direction, 1)};
  EXPECT_EQ(distinct.size(), 6u);
  double sum = 0.0, sum_of_products = 0.0;
  for (std::uint32_t pixel = 0; pixel < 100000; ++pixel) {
    const std::uint64_t key = path_key(pixel, 0);
    const float u = unit_float32(path_draw(key, 0, RandomPurpose::pixel_jitter, 0));
    const float v = unit_float32(path_draw(key, 0, RandomPurpose::pixel_jitter, 1));
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += u;
    sum_of_products += double(u) * v;  // independent dimensions: E[uv] = 1/4
  }
  EXPECT_NEAR(sum / 100000.0, 0.5, 0.005);
  EXPECT_NEAR(sum_of_products / 100000.0, 0.25, 0.005);
}

TEST(Sampling, BasisIsOrthonormalEvenAtThePoles) {
  for (const glm::vec3 n : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::normalize(glm::vec3(1, 2, 3))}) {
    const OrthonormalBasis basis = basis_around(n);
    EXPECT_NEAR(glm::dot(basis.tangent, basis.bitangent), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(basis.tangent, n), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(basis.tangent), 1.0f, 1e-6f);
  }
}

TEST(Morton, RoundTripsAndInterleaves) {
  EXPECT_EQ(morton2d_encode(1, 0), 1u);
  EXPECT_EQ(morton2d_encode(0, 1), 2u);
  EXPECT_EQ(morton2d_encode(3, 3), 15u);
  for (std::uint32_t x : {0u, 5u, 1023u, 65535u}) {
    for (std::uint32_t y : {0u, 7u, 4096u}) {
      const Point2u back = morton2d_decode(morton2d_encode(x, y));
      EXPECT_EQ(back.x, x);
      EXPECT_EQ(back.y, y);
    }
  }
}

TEST(RayOffset, MovesOffTheSurfaceAtEveryScale) {
  const glm::vec3 normal(0.0f, 0.0f, 1.0f);
  for (const float scale : {1e-3f, 1.0f, 1e3f, 1e6f}) {
    const glm::vec3 point(scale, -scale, scale);
    const glm::vec3 moved = offset_ray_origin(point, normal);
    EXPECT_GT(moved.z, point.z) << scale;
    EXPECT_EQ(moved.x, point.x);
    // A few ulps, or a fixed 2^-16 near the origin where ulps vanish: never a visible gap.
    EXPECT_LT(moved.z - point.z, std::max(scale * 1e-4f, 2e-5f)) << scale;
    const glm::vec3 below = offset_ray_origin(point, -normal);
    EXPECT_LT(below.z, point.z) << scale;
  }
  EXPECT_GT(offset_ray_origin(glm::vec3(0.0f), normal).z, 0.0f);
}

}  // namespace
}  // namespace wavetrace

namespace wavetrace {
namespace {

TEST(LaneTranspose, BitsAndLanesOfEightByEight) {
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (int trial = 0; trial < 200; ++trial) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const std::uint64_t bits = state ^ (state >> 29);
    const std::uint64_t transposed = transpose_bits_8x8(bits);
    for (int row = 0; row < 8; ++row) {
      for (int column = 0; column < 8; ++column) {
        ASSERT_EQ(bits >> (8 * row + column) & 1u, transposed >> (8 * column + row) & 1u) << trial;
      }
    }
  }
#if WAVETRACE_AVX2
  alignas(32) float matrix[8][8];
  __m256 rows[8];
  for (int row = 0; row < 8; ++row) {
    for (int lane = 0; lane < 8; ++lane) matrix[row][lane] = float(10 * row + lane);
    rows[row] = _mm256_load_ps(matrix[row]);
  }
  transpose_lanes_8x8(rows);
  for (int row = 0; row < 8; ++row) {
    alignas(32) float out[8];
    _mm256_store_ps(out, rows[row]);
    for (int lane = 0; lane < 8; ++lane) ASSERT_EQ(out[lane], matrix[lane][row]) << row << " " << lane;
  }
#endif
}

TEST(CheckedNarrowing, PassesWhatFitsAndNamesTheFieldOfWhatDoesNot) {
  EXPECT_EQ(checked_uint32(0xffffffffu, "x"), 0xffffffffu);
  try {
    checked_uint32(std::uint64_t{1} << 32, "hmq block offset");
    FAIL() << "2^32 does not fit";
  } catch (const std::length_error& error) {
    EXPECT_NE(std::string(error.what()).find("hmq block offset is 4294967296"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace wavetrace
