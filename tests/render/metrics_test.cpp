#include "render/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

namespace texlume::render {
namespace {

// Two flat images 0.1 apart: MSE 0.01, PSNR 20 dB exactly; SSIM of two flat
// images is its luminance term (2 a b + C1) / (a^2 + b^2 + C1), C1 = 0.01^2.
TEST(MaskedPsnr, FlatImagesHaveTheKnownAnswerInsideTheMaskOnly) {
  const cv::Mat a(32, 40, CV_32FC3, cv::Scalar::all(0.5)),
      b(32, 40, CV_32FC3, cv::Scalar::all(0.6));
  cv::Mat mask(32, 40, CV_8UC1, cv::Scalar(255));
  cv::Mat b_outside = b.clone();
  b_outside(cv::Rect(0, 0, 10, 32)).setTo(cv::Scalar::all(1.0));  // outside the mask below
  mask(cv::Rect(0, 0, 10, 32)).setTo(0);
  EXPECT_NEAR(MaskedPsnr(a, b, mask), 20.0, 1e-5);
  EXPECT_NEAR(MaskedPsnr(a, b_outside, mask), 20.0, 1e-5);
  EXPECT_EQ(MaskedPsnr(a, a, mask), 200.0);                           // identical: the cap
  EXPECT_EQ(MaskedPsnr(a, b, cv::Mat::zeros(32, 40, CV_8UC1)), 0.0);  // nothing inside
}

TEST(MaskedSsim, IdenticalIsOneAndFlatImagesHaveTheLuminanceTerm) {
  cv::Mat noise(48, 48, CV_32FC3);
  cv::randu(noise, cv::Scalar::all(0.0), cv::Scalar::all(1.0));
  const cv::Mat mask(48, 48, CV_8UC1, cv::Scalar(255));
  EXPECT_NEAR(MaskedSsim(noise, noise, mask), 1.0, 1e-5);
  const cv::Mat a(48, 48, CV_32FC3, cv::Scalar::all(0.5)),
      b(48, 48, CV_32FC3, cv::Scalar::all(0.6));
  const double c1 = 0.01 * 0.01;
  EXPECT_NEAR(MaskedSsim(a, b, mask), (2 * 0.5 * 0.6 + c1) / (0.25 + 0.36 + c1), 1e-4);
  // Structure lost: noise against its mean scores far below 1.
  EXPECT_LT(MaskedSsim(noise, cv::Mat(48, 48, CV_32FC3, cv::Scalar::all(0.5)), mask), 0.1);
}

TEST(MeasureView, ReducedFactorAveragesAndKeepsFlatDifferences) {
  const cv::Mat a(40, 40, CV_32FC3, cv::Scalar::all(0.5)),
      b(40, 40, CV_32FC3, cv::Scalar::all(0.6));
  const cv::Mat inside(40, 40, CV_8UC1, cv::Scalar(255));
  const ViewMetrics m = MeasureView("v.png", a, b, inside, 4);
  EXPECT_EQ(m.name, "v.png");
  EXPECT_NEAR(m.psnr, 20.0, 1e-5);
  EXPECT_NEAR(m.psnr_reduced, 20.0, 1e-5);
  // A checkerboard of 0 and 1 against flat 0.5: 6 dB at full resolution, and
  // identical once 2 x 2 blocks are averaged.
  cv::Mat checker(40, 40, CV_32FC3);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) checker.at<cv::Vec3f>(y, x) = cv::Vec3f::all((x + y) % 2);
  const cv::Mat grey(40, 40, CV_32FC3, cv::Scalar::all(0.5));
  const ViewMetrics c = MeasureView("c", checker, grey, inside, 2);
  EXPECT_NEAR(c.psnr, 10.0 * std::log10(4.0), 1e-5);
  EXPECT_EQ(c.psnr_reduced, 200.0);
  EXPECT_EQ(MeasureView("c", checker, grey, inside, 1).psnr_reduced, 0.0);  // not asked
}

}  // namespace
}  // namespace texlume::render
