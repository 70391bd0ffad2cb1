// The start-up CPU check's decision: which missing feature it names, and nothing when the
// CPU has what the build needs.
#include <string>

#include <gtest/gtest.h>

#include "wavetrace/build_config.hpp"
#include "wavetrace/memory/cpu_support.hpp"

namespace wavetrace {
namespace {

TEST(CpuSupport, NamesTheFirstFeatureTheBuildNeedsAndTheCpuLacks) {
  const CpuFeatures v3{true, true, true};
  EXPECT_EQ(cpu_support_error(v3, v3), nullptr);
  EXPECT_EQ(cpu_support_error(CpuFeatures{}, CpuFeatures{}), nullptr);  // a baseline build runs anywhere
  const std::string no_avx2 = cpu_support_error(CpuFeatures{false, true, true}, v3);
  EXPECT_NE(no_avx2.find("has no AVX2"), std::string::npos) << no_avx2;
  EXPECT_NE(no_avx2.find("-march=" WAVETRACE_ARCH), std::string::npos) << no_avx2;
  EXPECT_NE(no_avx2.find("-DWAVETRACE_ARCH=x86-64-v2"), std::string::npos) << no_avx2;
  EXPECT_NE(std::string(cpu_support_error(CpuFeatures{true, true, false}, v3)).find("has no BMI2"), std::string::npos);
  EXPECT_NE(std::string(cpu_support_error(CpuFeatures{true, false, true}, v3)).find("has no FMA"), std::string::npos);
  // This machine runs the tests, so it has what this build needs.
  EXPECT_EQ(cpu_support_error(running_cpu_features(), required_cpu_features()), nullptr);
  EXPECT_EQ(required_cpu_features().avx2, WAVETRACE_AVX2 != 0);
}

}  // namespace
}  // namespace wavetrace
