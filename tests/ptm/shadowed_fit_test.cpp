// The shadow-aware fit: on Lambertian pillars that shadow their ground, the horizon
// fitted from the capture alone predicts held-out lights' shadows, and refuses
// captures it cannot fit.
#include "ptm/shadowed_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/srgb.h"

namespace texlume::ptm {
namespace {

constexpr int kSize = 64;
constexpr double kRadPerDegree = std::numbers::pi / 180.0;
constexpr double kAmbient = 0.2;  // linear fraction a shadow keeps

// Square pillars 4 texels high on a plane (a period of 16 texels: 8 on top, ramps of
// 2 texels, 4 on the ground), heights in texel units: flat tops and ground that the
// pillars' steep sides shadow at low light.
double PillarProfile(int i) {
  const int p = i % 16;
  if (p < 4) return 0.0;
  if (p < 6) return 2.0 * (p - 3);
  if (p < 14) return 4.0;
  return 4.0 - 2.0 * (p - 13);
}

cv::Mat PillarHeights() {
  cv::Mat h(kSize, kSize, CV_64FC1);
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c)
      h.at<double>(r, c) = std::min(PillarProfile(r), PillarProfile(c));
  return h;
}

Eigen::Vector3d Light(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * kRadPerDegree, a = azimuth_deg * kRadPerDegree;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

// Lambert (albedo 0.7) with the bump's own cast shadows, as display RGB.
cv::Mat Render(const cv::Mat& heights, const HorizonMap& horizon, const Eigen::Vector3d& light) {
  cv::Mat image(kSize, kSize, CV_32FC3);
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c) {
      const int c0 = std::max(c - 1, 0), c1 = std::min(c + 1, kSize - 1);
      const int r0 = std::max(r - 1, 0), r1 = std::min(r + 1, kSize - 1);
      const double dh_dx = (heights.at<double>(r, c1) - heights.at<double>(r, c0)) / (c1 - c0);
      const double dh_dy = -(heights.at<double>(r1, c) - heights.at<double>(r0, c)) / (r1 - r0);
      const Eigen::Vector3d n = Eigen::Vector3d(-dh_dx, -dh_dy, 1.0).normalized();
      const double v = HorizonVisibility(horizon, static_cast<std::size_t>(r) * kSize + c, light,
                                         4.0 * kRadPerDegree);
      const double linear = 0.7 * std::max(0.0, n.dot(light)) * (v + (1.0 - v) * kAmbient);
      const float display = srgb::FromLinear(static_cast<float>(linear));
      image.at<cv::Vec3f>(r, c) = cv::Vec3f(display, display, display);
    }
  return image;
}

double MeanSquaredError(const std::vector<float>& rgb, const cv::Mat& image) {
  double sum = 0;
  for (int r = 0; r < kSize; ++r)
    for (int c = 0; c < kSize; ++c)
      for (int k = 0; k < 3; ++k) {
        const double d =
            rgb[(static_cast<std::size_t>(r) * kSize + c) * 3 + k] - image.at<cv::Vec3f>(r, c)[k];
        sum += d * d;
      }
  return sum / (kSize * kSize * 3.0);
}

TEST(FitShadowedPtm, PillarsHorizonFromItsCapturePredictsHeldOutShadows) {
  const cv::Mat heights = PillarHeights();
  const HorizonMap true_horizon = ComputeHorizonMap(heights, 16, 48);
  std::vector<cv::Mat> images;
  std::vector<Eigen::Vector3d> lights;
  for (const double elevation : {15.0, 30.0, 45.0, 60.0, 75.0})
    for (int a = 0; a < 6; ++a) {
      lights.push_back(Light(elevation, 60.0 * a + elevation));
      images.push_back(Render(heights, true_horizon, lights.back()));
    }
  const ShadowedPtm fitted = FitShadowedPtm(images, lights);
  EXPECT_GT(fitted.shadowing.height_scale, 0.0);
  // Attached shadows (n.l < 0) keep nothing and pull the median below the ambient.
  EXPECT_NEAR(fitted.shadowing.shadow_floor, kAmbient, 0.12);

  Ptm plain;
  {
    const std::vector<std::vector<float>> all(lights.size(),
                                              std::vector<float>(kSize * kSize, 1.f));
    plain = FitPtmToLitSamples(images, lights, all, PtmFormat::kLrgb, 6);
  }
  // Held-out low lights between the capture's azimuths: the shadows take away more
  // than half the plain PTM's error (measured: 0.0097 against 0.0333).
  double plain_error = 0, shadowed_error = 0;
  for (const double azimuth : {40.0, 130.0, 220.0, 310.0}) {
    const Eigen::Vector3d l = Light(20.0, azimuth);
    const cv::Mat truth = Render(heights, true_horizon, l);
    plain_error += MeanSquaredError(Relight(plain, l), truth);
    shadowed_error += MeanSquaredError(RelightShadowed(fitted, l), truth);
  }
  EXPECT_LT(shadowed_error, 0.5 * plain_error) << shadowed_error << " vs " << plain_error;

  // An atlas made of the fitted PTM finds the fit's horizon again from its own
  // normals (ShadowingOfPtm: the height scale is the refitted PTM's). Measured: a
  // mean difference of 13 % of the mean elevation (17 degrees).
  const SelfShadowing again = ShadowingOfPtm(fitted.ptm, fitted.shadowing);
  double difference = 0, elevation = 0;
  for (std::size_t i = 0; i < again.horizon.elevation_rad.size(); ++i) {
    difference +=
        std::abs(again.horizon.elevation_rad[i] - fitted.shadowing.horizon.elevation_rad[i]);
    elevation += fitted.shadowing.horizon.elevation_rad[i];
  }
  EXPECT_LT(difference, 0.25 * elevation) << difference / elevation;
  EXPECT_EQ(again.shadow_floor, fitted.shadowing.shadow_floor);
}

TEST(FitShadowedPtm, RefusesTooFewLightsAndMixedSizes) {
  std::vector<cv::Mat> images(7, cv::Mat(8, 8, CV_32FC3, cv::Scalar::all(0.5)));
  std::vector<Eigen::Vector3d> lights(7, Light(45, 0));
  EXPECT_THROW(FitShadowedPtm(images, lights), InputError);
  images.emplace_back(9, 8, CV_32FC3, cv::Scalar::all(0.5));
  lights.push_back(Light(30, 90));
  EXPECT_THROW(FitShadowedPtm(images, lights), InputError);
  ShadowedFitOptions o;
  o.height_scales.clear();
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace texlume::ptm
