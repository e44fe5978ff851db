#include "core/cubic_interpolation.h"

#include <gtest/gtest.h>

#include <numeric>

namespace texlume {
namespace {

// A plane whose texel (x, y) holds q(x, y), a quadratic.
double Quadratic(double x, double y) {
  return 0.3 + 0.02 * x - 0.01 * y + 0.004 * x * x - 0.003 * x * y + 0.002 * y * y;
}

cv::Mat QuadraticPlane(int width, int height) {
  cv::Mat plane(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) plane.at<float>(y, x) = static_cast<float>(Quadratic(x, y));
  return plane;
}

TEST(CatmullRom, WeightsSumToOneAndInterpolate) {
  for (const double t : {0.0, 0.1, 0.25, 0.5, 0.9, 1.0}) {
    const std::array<double, 4> w = CatmullRomWeights(t);
    EXPECT_NEAR(std::accumulate(w.begin(), w.end(), 0.0), 1.0, 1e-12) << t;
  }
  EXPECT_EQ(CatmullRomWeights(0.0), (std::array<double, 4>{0, 1, 0, 0}));
  EXPECT_EQ(CatmullRomWeights(1.0), (std::array<double, 4>{0, 0, 1, 0}));
  // Half way: -1/16, 9/16, 9/16, -1/16 (Keys 1981, a = -1/2).
  const std::array<double, 4> half = CatmullRomWeights(0.5);
  EXPECT_DOUBLE_EQ(half[0], -1.0 / 16);
  EXPECT_DOUBLE_EQ(half[1], 9.0 / 16);
}

// Away from the edges a Catmull-Rom read reproduces a quadratic between texel
// centres; a bilinear one is off by t (1 - t) times its second difference.
TEST(CatmullRom, ReproducesAQuadraticBetweenTexelCentres) {
  const cv::Mat plane = QuadraticPlane(12, 10);
  for (const auto& [x, y] : {std::pair{1.0, 1.0}, std::pair{4.5, 3.25}, std::pair{7.9, 6.5},
                             std::pair{9.999, 7.0}, std::pair{2.3, 7.75}}) {
    EXPECT_NEAR(CatmullRomTaps(plane.size(), x, y).Of(plane), Quadratic(x, y), 1e-5)
        << x << ", " << y;
  }
  // Half way between centres along x, bilinear misses by 0.004 / 4.
  const double bilinear = 0.5 * (Quadratic(4, 3) + Quadratic(5, 3));
  EXPECT_NEAR(bilinear - Quadratic(4.5, 3), 0.001, 1e-9);
}

TEST(CatmullRom, ClampsThePointAndTheTapsToThePlane) {
  const cv::Mat plane = QuadraticPlane(6, 5);
  // At a texel centre: the texel itself, also at the edges and corners.
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{5, 4}, std::pair{0, 4}, std::pair{3, 2}})
    EXPECT_FLOAT_EQ(static_cast<float>(CatmullRomTaps(plane.size(), x, y).Of(plane)),
                    plane.at<float>(y, x));
  // Beyond the plane: its edge texel.
  EXPECT_FLOAT_EQ(static_cast<float>(CatmullRomTaps(plane.size(), -3.0, 2.0).Of(plane)),
                  plane.at<float>(2, 0));
  EXPECT_FLOAT_EQ(static_cast<float>(CatmullRomTaps(plane.size(), 5.0, 40.0).Of(plane)),
                  plane.at<float>(4, 5));
  // A 1 x 1 plane reads its texel anywhere.
  const cv::Mat one(1, 1, CV_32FC1, cv::Scalar(0.7));
  EXPECT_FLOAT_EQ(static_cast<float>(CatmullRomTaps(one.size(), 0.4, -0.2).Of(one)), 0.7f);
}

TEST(CatmullRom, ReadsEveryChannelAsItsOwnPlane) {
  const cv::Mat a = QuadraticPlane(8, 7), b = 2.0 * QuadraticPlane(8, 7) - 0.5;
  cv::Mat interleaved;
  cv::merge(std::vector<cv::Mat>{a, b, a}, interleaved);
  const CatmullRomTaps taps(a.size(), 3.4, 0.6);
  float out[3] = {1, 2, 3};
  taps.AddScaledChannels(interleaved, -2.0, out);
  EXPECT_NEAR(out[0], 1 - 2 * taps.Of(a), 1e-5);
  EXPECT_NEAR(out[1], 2 - 2 * taps.Of(b), 1e-5);
  EXPECT_NEAR(out[2], 3 - 2 * taps.Of(a), 1e-5);
  float read[2];
  taps.Read(
      2, [&](int x, int y, int c) { return (c == 0 ? a : b).at<float>(y, x); }, read);
  EXPECT_NEAR(read[0], taps.Of(a), 1e-6);
  EXPECT_NEAR(read[1], taps.Of(b), 1e-6);
}

}  // namespace
}  // namespace texlume
