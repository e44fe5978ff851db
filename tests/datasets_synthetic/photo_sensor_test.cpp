#include "datasets_synthetic/photo_sensor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "core/errors.h"
#include "datasets_synthetic/renderer.h"

namespace texlume::datasets {
namespace {

cv::Mat Flat(double linear, int size = 200) {
  return cv::Mat(size, size, CV_32FC3, cv::Scalar::all(linear));
}

// Mean and standard deviation of channel `c` of an 8-bit photo back in linear.
std::pair<double, double> LinearStats(const cv::Mat& bgr8, int c, const cv::Rect& roi) {
  const cv::Mat linear = Srgb8ToLinear(bgr8)(roi);
  cv::Scalar mean, stddev;
  cv::meanStdDev(linear, mean, stddev);
  return {mean[c], stddev[c]};
}

TEST(ExposeOnSensor, OffIsTheCleanPhoto) {
  cv::Mat ramp(32, 64, CV_32FC3);
  for (int x = 0; x < 64; ++x) ramp.col(x).setTo(cv::Scalar::all(x / 63.0));
  std::mt19937_64 rng(1);
  const cv::Mat photo = ExposeOnSensor(ramp, SensorOptions{}, rng);
  EXPECT_EQ(cv::norm(photo, LinearToSrgb8(ramp), cv::NORM_INF), 0.0);
  EXPECT_FALSE(SensorOptions{}.Active());
}

// The photon-transfer model: variance = shot * x + read^2 on a flat field.
TEST(ExposeOnSensor, NoiseHasTheStatedVariance) {
  SensorOptions o;
  o.shot_noise = 0.001;
  o.read_noise = 0.01;
  std::mt19937_64 rng(7);
  const cv::Mat photo = ExposeOnSensor(Flat(0.25), o, rng);
  const double expected = std::sqrt(0.001 * 0.25 + 0.01 * 0.01);  // 0.0187
  for (int c = 0; c < 3; ++c) {
    const auto [mean, sigma] = LinearStats(photo, c, cv::Rect(0, 0, 200, 200));
    EXPECT_NEAR(mean, 0.25, 0.003);
    EXPECT_NEAR(sigma, expected, 0.1 * expected);
  }
  std::mt19937_64 again(7);
  EXPECT_EQ(cv::norm(photo, ExposeOnSensor(Flat(0.25), o, again), cv::NORM_INF), 0.0);
}

TEST(ExposeOnSensor, VignettingDarkensTheCornersByTheStatedShare) {
  SensorOptions o;
  o.vignetting = 0.3;
  std::mt19937_64 rng(1);
  const cv::Mat photo = ExposeOnSensor(Flat(0.5), o, rng);
  const double centre = LinearStats(photo, 1, cv::Rect(98, 98, 4, 4)).first;
  const double corner = LinearStats(photo, 1, cv::Rect(0, 0, 2, 2)).first;
  EXPECT_NEAR(centre, 0.5, 0.005);
  EXPECT_NEAR(corner / centre, 0.7, 0.02);
}

TEST(ExposeOnSensor, WhiteBalanceGainsAreDrawnInTheSpreadAndApplied) {
  SensorOptions o;
  o.white_balance_spread = 0.2;
  std::mt19937_64 rng(3);
  SensorDraw draw;
  const cv::Mat photo = ExposeOnSensor(Flat(0.4), o, rng, &draw);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GE(draw.white_balance[c], 0.8);
    EXPECT_LE(draw.white_balance[c], 1.2);
    EXPECT_NEAR(LinearStats(photo, c, cv::Rect(0, 0, 200, 200)).first, 0.4 * draw.white_balance[c],
                0.003);
  }
}

TEST(ExposeOnSensor, JpegLosesDetailButKeepsTheMean) {
  cv::Mat texture(128, 128, CV_32FC3);
  cv::RNG noise(5);
  noise.fill(texture, cv::RNG::UNIFORM, cv::Scalar::all(0.1), cv::Scalar::all(0.6));
  SensorOptions o;
  o.jpeg_quality = 50;
  std::mt19937_64 rng(1);
  const cv::Mat photo = ExposeOnSensor(texture, o, rng);
  const cv::Mat clean = LinearToSrgb8(texture);
  EXPECT_GT(cv::norm(photo, clean, cv::NORM_L1) / photo.total() / 3.0, 2.0);  // grey levels
  const cv::Scalar a = cv::mean(photo), b = cv::mean(clean);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 2.0);
}

TEST(SensorOptions, OutOfRangeIsRefused) {
  SensorOptions o;
  o.read_noise = -0.1;
  EXPECT_THROW(o.Check(), OptionError);
  o = {};
  o.vignetting = 1.0;
  EXPECT_THROW(o.Check(), OptionError);
  o = {};
  o.jpeg_quality = 101;
  EXPECT_THROW(o.Check(), OptionError);
  o.jpeg_quality = 90;
  EXPECT_NO_THROW(o.Check());
  EXPECT_TRUE(o.Active());
  EXPECT_EQ(o.ToJson()["jpeg_quality"], 90);
}

}  // namespace
}  // namespace texlume::datasets
