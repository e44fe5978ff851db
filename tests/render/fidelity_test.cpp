#include "render/fidelity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "core/image_io.h"

namespace texlume::render {
namespace {

const cv::Mat kAll(64, 64, CV_8UC1, cv::Scalar(255));

// A horizontal ramp of `slope` luma per pixel (grey, so luma = each channel).
cv::Mat Ramp(double slope) {
  cv::Mat ramp(64, 64, CV_32FC3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) ramp.at<cv::Vec3f>(y, x) = cv::Vec3f::all(0.2f + slope * x);
  return ramp;
}

TEST(Fidelity, IdenticalImagesScoreZeroEverywhere) {
  cv::Mat noise(64, 64, CV_32FC3);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0.2, 0.8);
  const AppearanceStats s = MeasureAppearance(noise, kAll);
  const FidelityMetrics m = CompareAppearance(s, s);
  EXPECT_EQ(m.luma_bias, 0.0);
  EXPECT_EQ(m.chroma_spread_ratio, 0.0);
  EXPECT_EQ(m.gradient_histogram_distance, 0.0);
  EXPECT_EQ(m.power_spectrum_db, 0.0);
  EXPECT_GT(s.gradient_p90, 0.1);
}

TEST(Fidelity, LumaAndChromaHaveTheKnownAnswers) {
  const cv::Mat grey(64, 64, CV_32FC3, cv::Scalar::all(0.5));
  const cv::Mat brighter(64, 64, CV_32FC3, cv::Scalar::all(0.55));
  const cv::Mat tinted(64, 64, CV_32FC3, cv::Scalar(0.6, 0.4, 0.5));  // R G B
  const AppearanceStats g = MeasureAppearance(grey, kAll), t = MeasureAppearance(tinted, kAll);
  EXPECT_NEAR(g.mean_luma, 0.5, 1e-6);
  EXPECT_NEAR(t.mean_luma, 0.2126 * 0.6 + 0.7152 * 0.4 + 0.0722 * 0.5, 1e-6);
  EXPECT_NEAR(t.mean_chroma_spread, 0.2, 1e-6);
  EXPECT_NEAR(CompareAppearance(g, MeasureAppearance(brighter, kAll)).luma_bias, 0.5 / 0.55 - 1,
              1e-6);
  // Twice as colourful: +100 %.
  const cv::Mat pale(64, 64, CV_32FC3, cv::Scalar(0.55, 0.45, 0.5));
  EXPECT_NEAR(CompareAppearance(t, MeasureAppearance(pale, kAll)).chroma_spread_ratio, 1.0, 1e-5);
}

// The sRGB curve is concave: an image with the same light but less contrast has
// no linear bias and a positive display bias.
TEST(Fidelity, LinearLumaBiasSeesTheLightAndNotTheContrast) {
  cv::Mat checker(64, 64, CV_32FC3), even(64, 64, CV_32FC3);
  const float dark = LinearToSrgb(0.1f), light = LinearToSrgb(0.3f), mid = LinearToSrgb(0.2f);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      checker.at<cv::Vec3f>(y, x) = cv::Vec3f::all((x + y) % 2 ? light : dark);
      even.at<cv::Vec3f>(y, x) = cv::Vec3f::all(mid);
    }
  const AppearanceStats truth = MeasureAppearance(checker, kAll);
  EXPECT_NEAR(truth.mean_linear_luma, 0.2, 1e-4);
  const FidelityMetrics smooth = CompareAppearance(MeasureAppearance(even, kAll), truth);
  EXPECT_NEAR(smooth.linear_luma_bias, 0.0, 1e-4);
  EXPECT_NEAR(smooth.luma_bias, mid / (0.5 * (dark + light)) - 1, 1e-4);
  EXPECT_GT(smooth.luma_bias, 0.03);
  cv::Mat brighter = even.clone();
  brighter.setTo(cv::Scalar::all(LinearToSrgb(0.22f)));
  EXPECT_NEAR(CompareAppearance(MeasureAppearance(brighter, kAll), truth).linear_luma_bias, 0.1,
              1e-4);
}

TEST(Fidelity, GradientHistogramDistanceIsTheShiftOfTheEdgeStrengths) {
  const AppearanceStats soft = MeasureAppearance(Ramp(0.011), kAll);
  const AppearanceStats sharp = MeasureAppearance(Ramp(0.021), kAll);
  EXPECT_NEAR(soft.gradient_p90, 0.011, 1e-5);
  const FidelityMetrics m = CompareAppearance(soft, sharp);
  EXPECT_NEAR(m.gradient_histogram_distance, 4 * kGradientBinWidth, 1e-9);  // bins 4 and 8
  EXPECT_NEAR(m.gradient_p90_truth, 0.021, 1e-5);
}

TEST(Fidelity, DoubledContrastIsSixDecibelsInEveryBand) {
  cv::Mat noise(64, 64, CV_32FC1);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.05);
  cv::Mat a, b;
  cv::merge(std::vector<cv::Mat>(3, noise + 0.4), a);
  cv::merge(std::vector<cv::Mat>(3, 2 * noise + 0.4), b);
  const FidelityMetrics m =
      CompareAppearance(MeasureAppearance(b, kAll), MeasureAppearance(a, kAll));
  EXPECT_NEAR(m.power_spectrum_db, 10 * std::log10(4.0), 1e-3);
  const double noise_mean = cv::mean(noise)[0];  // b is brighter by it
  EXPECT_NEAR(m.luma_bias, (0.4 + 2 * noise_mean) / (0.4 + noise_mean) - 1, 1e-5);
}

TEST(Fidelity, OnlyTheMaskCountsAndBadInputIsRefused) {
  cv::Mat half(64, 64, CV_32FC3, cv::Scalar::all(0.3));
  half(cv::Rect(32, 0, 32, 64)).setTo(cv::Scalar::all(0.9));
  cv::Mat left = cv::Mat::zeros(64, 64, CV_8UC1);
  left(cv::Rect(0, 0, 32, 64)).setTo(255);
  EXPECT_NEAR(MeasureAppearance(half, left).mean_luma, 0.3, 1e-6);
  EXPECT_EQ(MeasureAppearance(half, cv::Mat::zeros(64, 64, CV_8UC1)).mean_luma, 0.0);
  EXPECT_THROW(MeasureAppearance(cv::Mat(64, 64, CV_8UC3), kAll), std::invalid_argument);
  EXPECT_THROW(MeasureAppearance(half, cv::Mat(32, 32, CV_8UC1)), std::invalid_argument);
}

}  // namespace
}  // namespace texlume::render
