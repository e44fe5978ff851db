#include "synth/colour_sample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/image_io.h"

namespace texlume::synth {
namespace {

cv::Mat RandomColour(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  cv::Mat image(height, width, CV_32FC3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      // Drawn one at a time, last first: a call's arguments are evaluated in an
      // unspecified order (GCC right to left, clang left to right).
      const float c2 = u(rng), c1 = u(rng), c0 = u(rng);
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(c0, c1, c2);
    }
  return image;
}

// The baked PTM shades like a Lambertian surface in the display domain:
// L(l) = l_z^(1/2.2) from 15 to 90 degrees of elevation (within 0.05: a
// biquadratic is 0.040 off at 45 degrees), the colour as given.
TEST(LambertianPtm, LuminanceFollowsTheDisplayDomainCosineAndColourIsKept) {
  const cv::Mat colour = RandomColour(4, 3, 1);
  const ptm::Ptm ptm = LambertianPtm(colour);
  ASSERT_EQ(ptm.format, ptm::PtmFormat::kLrgb);
  for (const double elevation_deg : {20.0, 45.0, 70.0, 90.0})
    for (const double azimuth_deg : {0.0, 100.0, 230.0}) {
      const double e = elevation_deg * std::numbers::pi / 180.0,
                   a = azimuth_deg * std::numbers::pi / 180.0;
      const double l = ptm::EvaluatePolynomial(ptm.Coefficients(5), std::cos(e) * std::cos(a),
                                               std::cos(e) * std::sin(a));
      EXPECT_NEAR(l, std::pow(std::sin(e), 1.0 / 2.2), 0.05) << elevation_deg;
    }
  for (int k = 0; k < 3; ++k)
    EXPECT_FLOAT_EQ(ptm.colour[7 * 3 + static_cast<std::size_t>(k)], colour.at<cv::Vec3f>(1, 3)[k]);
}

// Relit = gain x Lambert factor x linear colour, and the gains' mean agrees.
TEST(ColourSample, RelightsLambertianInTheLinearDomain) {
  const cv::Mat colour = RandomColour(8, 6, 2);
  const ColourSample sample(colour);
  EXPECT_EQ(sample.NumFeatures(), 3);
  EXPECT_TRUE(sample.Blendable());
  EXPECT_EQ(sample.Domain(), PhotoDomain::kLinear);
  const Eigen::Vector3d high(0.0, 0.6, 0.8), below(0.0, 0.0, -1.0);
  const FaceLighting lighting{Eigen::Vector3d::UnitZ(), {{high, 2.0}, {below, 5.0}}, {}};
  EXPECT_NEAR(ColourSample::LambertFactor(lighting), 1.6, 1e-12);
  const std::vector<cv::Mat> relit = sample.Relight(sample.Reduced(0), lighting, 0.5);
  double sum = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) {
        const float expected = 0.5f * 1.6f * SrgbToLinear(colour.at<cv::Vec3f>(y, x)[c]);
        EXPECT_NEAR(relit[static_cast<std::size_t>(c)].at<float>(y, x), expected, 1e-5);
        sum += relit[static_cast<std::size_t>(c)].at<float>(y, x);
      }
  EXPECT_NEAR(sample.RelitLinearSum(lighting, 48), sum / 0.5, 1e-3);
  // Features are the display colour, untouched by a frame's turn.
  float features[3];
  sample.FeaturesAt(Eigen::Vector2d(2.5, 1.5), features);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(features[c], colour.at<cv::Vec3f>(1, 2)[c]);
}

}  // namespace
}  // namespace texlume::synth
