#include "synth/overlap_placement.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

namespace texlume::synth {
namespace {

// `count` feature planes of smooth noise (seeded), size x size texels.
std::vector<cv::Mat> SmoothFeatures(int size, int count, unsigned seed) {
  cv::RNG rng(seed);
  std::vector<cv::Mat> planes(static_cast<std::size_t>(count));
  for (cv::Mat& p : planes) {
    p.create(size, size, CV_32FC1);
    rng.fill(p, cv::RNG::NORMAL, 0.0, 1.0);
    cv::GaussianBlur(p, p, cv::Size(), 2.0);
  }
  return planes;
}

// The overlap an L-shaped strip (the patch's top and left `strip` texels) would
// have if the neighbours' patches came from `from` in the sample.
OverlapTexels StripFrom(const std::vector<cv::Mat>& features, cv::Size patch, cv::Point from,
                        int strip) {
  OverlapTexels overlap;
  overlap.patch = patch;
  for (int j = 0; j < patch.height; ++j)
    for (int i = 0; i < patch.width; ++i) {
      if (j >= strip && i >= strip) continue;
      overlap.texels.push_back(j * patch.width + i);
      for (const cv::Mat& f : features)
        overlap.targets.push_back(f.at<float>(from.y + j, from.x + i));
    }
  return overlap;
}

TEST(OverlapPlacement, HalvingsKeepSixBlocksAndPayOff) {
  const std::vector<cv::Mat> large = SmoothFeatures(256, 1, 1);
  const OverlapPlacement on_large(large);
  EXPECT_EQ(on_large.Halvings(cv::Size(40, 30)), 2);
  EXPECT_EQ(on_large.Halvings(cv::Size(40, 20)), 1);  // 20 / 4 < 6 blocks
  EXPECT_EQ(on_large.Halvings(cv::Size(11, 40)), 0);
  // A patch nearly the sample's size: few placements, nothing to refine.
  EXPECT_EQ(on_large.Halvings(cv::Size(240, 240)), 0);
}

// Coarse to fine finds the place the overlap was cut from, at full density, with
// no error, wherever it is (also off the blocks' grid).
TEST(OverlapPlacement, CoarseToFineFindsWhereTheOverlapWasCut) {
  const std::vector<cv::Mat> features = SmoothFeatures(160, 6, 7);
  OverlapPlacement placement(features);
  const cv::Size patch(36, 32);
  ASSERT_EQ(placement.Halvings(patch), 2);
  std::mt19937_64 rng(3);
  for (const cv::Point from : {cv::Point(57, 33), cv::Point(0, 0), cv::Point(121, 127),
                               cv::Point(90, 5), cv::Point(13, 101)}) {
    const OverlapTexels overlap = StripFrom(features, patch, from, 6);
    const OverlapPlacement::Placement p = placement.Pick(overlap, 0.0, rng);
    EXPECT_EQ(p.texel, from);
    EXPECT_NEAR(p.error, 0.0, 1e-9);
    EXPECT_EQ(p.error, overlap.SumOfSquares(features, p.texel));
  }
}

// The last placements at full density lie past the coarse grid's last one when
// neither the sample nor the patch is a whole number of blocks (162 = 40 x 4 + 2,
// 33 x 29 texels): the last coarse column and row reach them.
TEST(OverlapPlacement, CoarseToFineReachesTheSamplesLastPlacements) {
  const std::vector<cv::Mat> features = SmoothFeatures(162, 6, 13);
  OverlapPlacement placement(features);
  const cv::Size patch(33, 29);
  ASSERT_EQ(placement.Halvings(patch), 2);
  std::mt19937_64 rng(9);
  for (const cv::Point from : {cv::Point(129, 133), cv::Point(127, 131), cv::Point(0, 133)}) {
    const OverlapPlacement::Placement p =
        placement.Pick(StripFrom(features, patch, from, 6), 0.0, rng);
    EXPECT_EQ(p.texel, from);
  }
}

// With no halving the pick is the exhaustive one: the same placement from the
// same random stream as PickWithinTolerance over every placement's error, with
// targets off the sample (noise) so that several are within the tolerance.
TEST(OverlapPlacement, WithoutHalvingsEveryPlacementIsScored) {
  const std::vector<cv::Mat> features = SmoothFeatures(48, 3, 11);
  OverlapPlacement placement(features);
  const cv::Size patch(10, 9);
  ASSERT_EQ(placement.Halvings(patch), 0);
  OverlapTexels overlap = StripFrom(features, patch, cv::Point(20, 30), 3);
  std::mt19937 noise_rng(17);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  for (float& t : overlap.targets) t += noise(noise_rng);
  std::mt19937_64 a(5), b(5);
  const OverlapPlacement::Placement p = placement.Pick(overlap, 0.5, a);
  std::vector<cv::Mat> targets(features.size());
  for (cv::Mat& t : targets) t = cv::Mat::zeros(patch, CV_32FC1);
  cv::Mat mask = cv::Mat::zeros(patch, CV_32FC1);
  for (std::size_t m = 0; m < overlap.texels.size(); ++m) {
    const int i = overlap.texels[m] % patch.width, j = overlap.texels[m] / patch.width;
    mask.at<float>(j, i) = 1.0f;
    for (std::size_t c = 0; c < features.size(); ++c)
      targets[c].at<float>(j, i) = overlap.targets[m * features.size() + c];
  }
  const cv::Mat errors = MaskedSsdBruteForce(features, targets, mask);
  double least = 0.0;
  cv::minMaxLoc(errors, &least);
  ASSERT_GT(cv::countNonZero(errors <= least * 1.5), 1);  // a choice to make
  EXPECT_EQ(p.texel, PickWithinTolerance(errors, 0.5, b));
  EXPECT_NEAR(p.error, overlap.SumOfSquares(features, p.texel), 1e-3);
}

}  // namespace
}  // namespace texlume::synth
