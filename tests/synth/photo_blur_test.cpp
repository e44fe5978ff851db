#include "synth/photo_blur.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace texlume::synth {
namespace {

// A material-like texture: white noise with a falling spectrum (blurred by
// one cell) plus a finer share, one instance per seed.
cv::Mat Instance(int size, std::uint32_t seed) {
  cv::Mat noise(size, size, CV_32FC1), fine(size, size, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  rng.fill(fine, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(), 1.0);
  return 0.5f + 0.1f * noise + 0.02f * fine;
}

// A face's cells: a triangle filling most of a square grid.
cv::Mat TriangleMask(int size) {
  cv::Mat mask = cv::Mat::zeros(size, size, CV_32FC1);
  const std::vector<cv::Point> corners = {{1, 1}, {size - 2, 1}, {1, size - 2}};
  cv::fillConvexPoly(mask, corners, cv::Scalar(1.0));
  return mask;
}

// Photo `photo` sees 24 faces of another instance of the sample's material,
// blurred by `sigma` cells, with white noise of `noise` (the sample's texture
// has a standard deviation of about 0.05).
void AddFaces(PhotoBlurEstimator& estimator, std::size_t photo, double sigma, double noise,
              std::uint32_t seed) {
  constexpr int kGrid = 28, kSize = 160;
  const cv::Mat sample = Instance(kSize, 1), object = Instance(kSize, seed);
  cv::Mat seen = object.clone();
  if (sigma > 0.0) cv::GaussianBlur(object, seen, cv::Size(), sigma);
  cv::Mat photo_noise(seen.size(), CV_32FC1);
  cv::RNG rng(seed + 7);
  rng.fill(photo_noise, cv::RNG::NORMAL, 0.0, noise);
  seen += photo_noise;
  const cv::Mat mask = TriangleMask(kGrid);
  std::mt19937 place(seed);
  std::uniform_int_distribution<int> at(0, kSize - kGrid);
  for (int face = 0; face < PhotoBlurEstimator::kFacesPerPhoto; ++face) {
    // Drawn one at a time, last first: a call's arguments are evaluated in an
    // unspecified order (GCC right to left, clang left to right).
    const int photo_y = at(place), photo_x = at(place);
    const int sample_y = at(place), sample_x = at(place);
    const cv::Rect photo_window(photo_x, photo_y, kGrid, kGrid);
    const cv::Rect sample_window(sample_x, sample_y, kGrid, kGrid);
    estimator.Add(photo, seen(photo_window).clone(), sample(sample_window).clone(), mask);
  }
}

TEST(MeasureBands, AConstantHasNoEnergyAndMaskedCellsDoNotCount) {
  cv::Mat grid(20, 20, CV_32FC1, cv::Scalar(0.4));
  const cv::Mat mask = TriangleMask(20);
  // Outside the mask, values that would ring through an unmasked blur.
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 20; ++i)
      if (mask.at<float>(j, i) == 0.0f) grid.at<float>(j, i) = 5.0f;
  const BandEnergies e = MeasureBands(grid, mask);
  EXPECT_GT(e.cells, 20);
  EXPECT_NEAR(e.fine, 0.0, 1e-9);
  EXPECT_NEAR(e.middle, 0.0, 1e-9);
}

TEST(MeasureBands, BlurMovesEnergyOutOfTheFineBandFirst) {
  const cv::Mat grid = Instance(48, 3);
  const cv::Mat everywhere = cv::Mat::ones(48, 48, CV_32FC1);
  const BandEnergies sharp = MeasureBands(grid, everywhere);
  const BandEnergies blurred = MeasureBands(MaskedGaussian(grid, everywhere, 0.8), everywhere);
  EXPECT_LT(blurred.fine / blurred.middle, 0.6 * sharp.fine / sharp.middle);
}

TEST(SigmaMatchingRatio, InterpolatesBetweenCandidatesAndClampsAtTheEnds) {
  const std::vector<double> ratio = {1.0, 0.8, 0.5, 0.3};
  EXPECT_DOUBLE_EQ(SigmaMatchingRatio(1.2, ratio, 0.1), 0.0);  // sharper than the sample
  EXPECT_DOUBLE_EQ(SigmaMatchingRatio(1.0, ratio, 0.1), 0.0);
  EXPECT_NEAR(SigmaMatchingRatio(0.8, ratio, 0.1), 0.1, 1e-12);
  EXPECT_NEAR(SigmaMatchingRatio(0.65, ratio, 0.1), 0.15, 1e-12);
  EXPECT_NEAR(SigmaMatchingRatio(0.1, ratio, 0.1), 0.3, 1e-12);  // blurrier than the last
}

TEST(BlurOnGrid, ScalesByThePixelsSpanAndAddsItsIntegrationOnAFinerGrid) {
  EXPECT_DOUBLE_EQ(BlurOnGrid(0.4, 3, 3), 0.4);
  // Four levels finer: a photo pixel spans 2 cells, its box adds (4 - 1) / 12.
  EXPECT_NEAR(BlurOnGrid(0.4, 3, -1), std::sqrt(0.8 * 0.8 + 0.25), 1e-12);
  EXPECT_NEAR(BlurOnGrid(0.0, 3, -1), 0.5, 1e-12);
  // Four levels coarser: half a cell per pixel, no box beyond the reduction's.
  EXPECT_NEAR(BlurOnGrid(0.4, 3, 7), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(BlurOnGrid(2.0, 20, 0), kMaxBlurCells);
}

TEST(PhotoBlurEstimator, RecoversAKnownBlurFromAnotherInstanceOfTheMaterial) {
  PhotoBlurEstimator estimator(3);
  AddFaces(estimator, 0, 0.0, 0.0, 11);
  AddFaces(estimator, 1, 0.5, 0.0, 12);
  AddFaces(estimator, 2, 1.0, 0.0, 13);
  const std::vector<double> sigma = estimator.SolvePerPhoto();
  EXPECT_LT(sigma[0], 0.15);
  EXPECT_NEAR(sigma[1], 0.5, 0.12);
  EXPECT_NEAR(sigma[2], 1.0, 0.12);
}

TEST(PhotoBlurEstimator, NoiseMakesItErrTowardLessBlur) {
  PhotoBlurEstimator estimator(1);
  AddFaces(estimator, 0, 0.8, 0.01, 21);
  const double sigma = estimator.SolvePerPhoto()[0];
  EXPECT_LE(sigma, 0.8 + 0.05);
  EXPECT_GT(sigma, 0.4);
}

TEST(PhotoBlurEstimator, EachPhotoTakesItsCamerasMedian) {
  PhotoBlurEstimator estimator(5);
  AddFaces(estimator, 0, 0.6, 0.0, 31);
  AddFaces(estimator, 1, 0.6, 0.0, 32);
  AddFaces(estimator, 2, 0.0, 0.0, 33);  // an outlier (e.g. hard shadows)
  AddFaces(estimator, 3, 1.2, 0.0, 34);  // another camera
  // Photo 4 has no faces: its camera's median.
  const std::vector<double> sigma = estimator.SolvePerCamera({1, 1, 1, 2, 1});
  const std::vector<double> own = estimator.SolvePerPhoto();
  for (std::size_t n : {0u, 1u, 2u, 4u}) {
    EXPECT_NEAR(sigma[n], 0.6, 0.12) << "photo " << n;
  }
  EXPECT_DOUBLE_EQ(sigma[3], own[3]);
  EXPECT_DOUBLE_EQ(own[4], 0.0);
  EXPECT_DOUBLE_EQ(PhotoBlurEstimator(2).SolvePerCamera({1, 2})[0], 0.0);
}

}  // namespace
}  // namespace texlume::synth
