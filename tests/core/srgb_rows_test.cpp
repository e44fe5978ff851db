#include "core/srgb_rows.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/srgb.h"

namespace texlume::srgb {
namespace {

// Values across and beyond [0, 1]: both linear segments' ends, the tables' last
// interval, NaN, infinities, signed zeros, subnormals, then random values (seeded).
std::vector<float> Values() {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> v{0.0f,
                       -0.0f,
                       1.0f,
                       kDisplayLinearUpTo,
                       std::nextafter(kDisplayLinearUpTo, 1.0f),
                       kLinearUpTo,
                       std::nextafter(kLinearUpTo, 1.0f),
                       std::nextafter(1.0f, 0.0f),
                       1.0f - 0.5f / Tables::kIntervals,
                       std::numeric_limits<float>::quiet_NaN(),
                       inf,
                       -inf,
                       -0.25f,
                       1.5f,
                       std::numeric_limits<float>::denorm_min(),
                       1e-30f};
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.1f, 1.1f);
  while (v.size() < 203) v.push_back(u(rng));
  return v;
}

// Bit for bit: a row function's outputs against the scalar conversion's.
void ExpectSameBits(const std::vector<float>& got, const std::vector<float>& expected,
                    const std::vector<float>& in) {
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i)
    EXPECT_EQ(std::memcmp(&got[i], &expected[i], sizeof(float)), 0)
        << "value " << i << " (" << in[i] << "): " << got[i] << " against " << expected[i];
}

// Every length from 0 to 20 (whole steps of eight and the rest one at a time), and
// every value of Values() in one long row.
std::vector<std::size_t> Lengths() {
  std::vector<std::size_t> n;
  for (std::size_t k = 0; k <= 20; ++k) n.push_back(k);
  n.push_back(Values().size());
  return n;
}

// Without AVX2 the rows are the scalar conversions themselves: nothing to compare.
#define SKIP_WITHOUT_AVX2() \
  if (!RowsUseAvx2()) GTEST_SKIP() << "this processor (or build) takes the scalar path"

TEST(SrgbRows, AddWeightedLinearIsToLinearToTheBit) {
  SKIP_WITHOUT_AVX2();
  const std::vector<float> in = Values();
  for (const std::size_t n : Lengths()) {
    const std::vector<float> row(in.begin(), in.begin() + static_cast<std::ptrdiff_t>(n));
    std::vector<float> got(n), expected(n);
    for (std::size_t i = 0; i < n; ++i) got[i] = expected[i] = 0.01f * static_cast<float>(i);
    AddWeightedLinear(row.data(), 0.7f, static_cast<int>(n), got.data());
    for (std::size_t i = 0; i < n; ++i) expected[i] += 0.7f * ToLinear(row[i]);
    ExpectSameBits(got, expected, row);
  }
}

// At scale 1 the values' segment ends are FromLinear's own; at 1.3 other values.
TEST(SrgbRows, ScaledFromLinearIsFromLinearToTheBit) {
  SKIP_WITHOUT_AVX2();
  const std::vector<float> in = Values();
  for (const float scale : {1.0f, 1.3f})
    for (const std::size_t n : Lengths()) {
      const std::vector<float> row(in.begin(), in.begin() + static_cast<std::ptrdiff_t>(n));
      std::vector<float> got(n), expected(n);
      ScaledFromLinear(row.data(), scale, static_cast<int>(n), got.data());
      for (std::size_t i = 0; i < n; ++i) expected[i] = FromLinear(scale * row[i]);
      ExpectSameBits(got, expected, row);
    }
}

// The conversions themselves, at known values (in a row of 8: one vector step where
// there is AVX2): 0 and 1 are fixed points, the linear segment is proportional, a mid
// grey decodes to about 0.214, and a round trip returns the display values.
TEST(SrgbRows, KnownValues) {
  const std::vector<float> display{0.0f, 1.0f, 0.02f, 0.5f, 0.25f, 0.75f, 0.9f, 0.1f};
  std::vector<float> linear(display.size(), 0.0f);
  AddWeightedLinear(display.data(), 1.0f, 8, linear.data());
  EXPECT_EQ(linear[0], 0.0f);
  EXPECT_NEAR(linear[1], 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(linear[2], 0.02f / 12.92f);
  EXPECT_NEAR(linear[3], 0.2140411f, 1e-6f);
  std::vector<float> back(display.size());
  ScaledFromLinear(linear.data(), 1.0f, 8, back.data());
  for (std::size_t i = 0; i < display.size(); ++i) EXPECT_NEAR(back[i], display[i], 1e-5f);
}

// The curves' slopes against central differences of the exact powers, on both
// segments and at the ends of [0, 1] (0 outside, where the conversions clamp).
TEST(SrgbSlopes, MatchTheCurvesDerivatives) {
  const auto decode = [](double v) {
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  };
  const auto encode = [](double v) {
    return v <= 0.0031308 ? v * 12.92 : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  };
  const double h = 1e-6;
  for (const float v : {0.01f, 0.04f, 0.05f, 0.2f, 0.5f, 0.9f, 0.999f}) {
    const double to = (decode(v + h) - decode(v - h)) / (2 * h);
    EXPECT_NEAR(ToLinearSlope(v, ToLinear(v)), to, 1e-5 * to) << v;
  }
  for (const float v : {0.001f, 0.003f, 0.004f, 0.05f, 0.2f, 0.5f, 0.999f}) {
    const double from = (encode(v + h) - encode(v - h)) / (2 * h);
    EXPECT_NEAR(FromLinearSlope(v, FromLinear(v)), from, 1e-5 * from) << v;
  }
  for (const float v : {-0.1f, 0.0f, 1.0f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
    EXPECT_EQ(ToLinearSlope(v, ToLinear(v)), 0.0f) << v;
    EXPECT_EQ(FromLinearSlope(v, FromLinear(v)), 0.0f) << v;
  }
}

}  // namespace
}  // namespace texlume::srgb
