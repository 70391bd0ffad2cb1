// Light sampling: the alias table picks each light with its share of the power, and a
// saved sampler whose weights do not rise from 0 to 1 is refused.
#include <array>
#include <stdexcept>

#include <gtest/gtest.h>

#include "wavetrace/scene/lights.hpp"

namespace wavetrace {
namespace {

LightSampler::EmissiveTriangle light_with_emission(float tag) {
  LightSampler::EmissiveTriangle light{};
  light.edge1 = {1, 0, 0};
  light.edge2 = {0, 1, 0};
  light.normal = {0, 0, 1};
  light.emission = {tag, tag, tag};
  light.pdf_area = 1.0f;
  return light;
}

TEST(LightSampler, AliasTablePicksEachLightWithItsShare) {
  const std::array<double, 5> share = {0.05, 0.4, 0.05, 0.3, 0.2};
  std::vector<LightSampler::EmissiveTriangle> lights;
  std::vector<float> cumulative;
  double running = 0.0;
  for (std::size_t i = 0; i < share.size(); ++i) {
    lights.push_back(light_with_emission(float(i + 1)));
    running += share[i];
    cumulative.push_back(float(running));
  }
  cumulative.back() = 1.0f;
  const LightSampler sampler(lights, cumulative);
  std::array<std::size_t, 5> picked{};
  constexpr std::size_t kSamples = 200000;
  for (std::size_t s = 0; s < kSamples; ++s) {
    const float u = (float(s) + 0.5f) / float(kSamples);
    const LightSample sample = sampler.sample(u, 0.25f, 0.5f);
    const auto index = static_cast<std::size_t>(sample.emission.x) - 1;
    ASSERT_LT(index, share.size());
    ++picked[index];
    EXPECT_EQ(sample.normal, glm::vec3(0, 0, 1));
  }
  for (std::size_t i = 0; i < share.size(); ++i) {
    EXPECT_NEAR(double(picked[i]) / kSamples, share[i], 1e-4) << "light " << i;
  }
}

TEST(LightSampler, RefusesWeightsThatDoNotRiseToOne) {
  const std::vector<LightSampler::EmissiveTriangle> two = {light_with_emission(1), light_with_emission(2)};
  EXPECT_THROW(LightSampler(two, {0.7f, 0.4f}), std::invalid_argument);
  EXPECT_THROW(LightSampler(two, {0.5f, 1.5f}), std::invalid_argument);
  EXPECT_THROW(LightSampler(two, {0.5f}), std::invalid_argument);
  EXPECT_NO_THROW(LightSampler(two, {0.5f, 1.0f}));
}

}  // namespace
}  // namespace wavetrace
