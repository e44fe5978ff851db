#include "synth/detail_transfer.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "ptm/coefficient_space.h"

namespace texlume::synth {
namespace {

// An LRGB PTM of smooth random coefficients (blurred noise, seeded), so that each
// texel's 3 x 3 window is its own and a few principal components carry them.
ptm::Ptm SmoothPtm(int size, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, size, size);
  for (int c = 0; c < 6; ++c) {
    cv::Mat plane(size, size, CV_32FC1);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) plane.at<float>(y, x) = n(rng);
    cv::GaussianBlur(plane, plane, cv::Size(), 1.5);
    for (std::size_t t = 0; t < p.NumTexels(); ++t)
      p.Coefficients(t)[c] =
          0.2f * plane.at<float>(static_cast<int>(t) / size, static_cast<int>(t) % size);
  }
  for (std::size_t t = 0; t < p.NumTexels(); ++t) p.Coefficients(t)[5] += 0.5f;
  std::fill(p.colour.begin(), p.colour.end(), 1.0f);
  return p;
}

// The orthonormal luminance coefficients of texel (x, y).
Eigen::Matrix<double, 6, 1> Orthonormal(const ptm::Ptm& p, int x, int y) {
  Eigen::Matrix<double, 6, 1> a;
  const float* raw = p.Coefficients(static_cast<std::size_t>(y * p.width + x));
  for (int m = 0; m < 6; ++m) a[m] = raw[m];
  return ptm::OrthonormalBasis::Hemisphere().ToOrthonormal() * a;
}

// A patch of `size` cells at `at` in the sample (texels, density level 0: a cell a
// texel) whose correction takes each cell's coarse coefficients to those of the
// texel `to - at` away.
TrianglePatch PatchCorrectedToward(const ptm::Ptm& p, cv::Size size, cv::Point at, cv::Point to) {
  TrianglePatch patch;
  patch.sample_x = at.x, patch.sample_y = at.y;
  patch.correction.assign(6, cv::Mat());
  for (cv::Mat& m : patch.correction) m = cv::Mat::zeros(size, CV_32FC1);
  for (int j = 0; j < size.height; ++j)
    for (int i = 0; i < size.width; ++i) {
      const Eigen::Matrix<double, 6, 1> change =
          Orthonormal(p, to.x + i, to.y + j) - Orthonormal(p, at.x + i, at.y + j);
      for (int m = 0; m < 6; ++m)
        patch.correction[static_cast<std::size_t>(m)].at<float>(j, i) =
            static_cast<float>(change[m]);
    }
  return patch;
}

// Every cell inside the grid's edge (whose windows the grid clamps) takes its
// detail from the texel `to` + (i, j).
void ExpectSourcesFrom(const TrianglePatch& patch, cv::Point to) {
  ASSERT_EQ(patch.detail_source.type(), CV_32FC2);
  for (int j = 1; j + 1 < patch.detail_source.rows; ++j)
    for (int i = 1; i + 1 < patch.detail_source.cols; ++i) {
      const cv::Vec2f s = patch.detail_source.at<cv::Vec2f>(j, i);
      EXPECT_NEAR(s[0], to.x + i, 1e-3) << "cell " << i << ", " << j;
      EXPECT_NEAR(s[1], to.y + j, 1e-3) << "cell " << i << ", " << j;
    }
}

TEST(DetailTransfer, AnUncorrectedPatchKeepsItsOwnDetail) {
  const ptm::Ptm p = SmoothPtm(48, 3);
  const PtmSample sample(p);
  cv::Mat band;
  const DetailDictionary dictionary(sample, 0, band);
  ASSERT_TRUE(dictionary.Usable());
  ASSERT_EQ(band.channels(), static_cast<int>(sample.Values().size()));
  TrianglePatch patch = PatchCorrectedToward(p, cv::Size(13, 11), {9, 17}, {9, 17});
  dictionary.Transfer(patch, 0);
  EXPECT_EQ(patch.detail_level, 0);
  ExpectSourcesFrom(patch, {9, 17});
}

// A correction toward another place of the sample brings that place's detail:
// the cells the index is not asked (half of them) find it too, by their neighbours.
TEST(DetailTransfer, ACorrectedPatchTakesTheDetailOfThePlaceItWasCorrectedToward) {
  const ptm::Ptm p = SmoothPtm(48, 5);
  const PtmSample sample(p);
  cv::Mat band;
  const DetailDictionary dictionary(sample, 0, band);
  for (const cv::Point to : {cv::Point(25, 4), cv::Point(3, 30), cv::Point(30, 31)}) {
    TrianglePatch patch = PatchCorrectedToward(p, cv::Size(12, 12), {6, 8}, to);
    dictionary.Transfer(patch, 0);
    ExpectSourcesFrom(patch, to);
  }
}

// Every cell of a patch's grid has a window centre of the sample ([1, 46] x [1, 46]
// for a 48 x 48 sample) as its source.
void ExpectSourcesAreWindowCentres(const TrianglePatch& patch) {
  for (int j = 0; j < patch.detail_source.rows; ++j)
    for (int i = 0; i < patch.detail_source.cols; ++i) {
      const cv::Vec2f s = patch.detail_source.at<cv::Vec2f>(j, i);
      EXPECT_GE(s[0], 1.0f) << i << ", " << j;
      EXPECT_LE(s[0], 46.0f) << i << ", " << j;
      EXPECT_GE(s[1], 1.0f) << i << ", " << j;
      EXPECT_LE(s[1], 46.0f) << i << ", " << j;
    }
}

// Patches against the sample's right and bottom edges: cells there lie beyond every
// window's centre. In a patch one cell high, the last cell is not asked (the
// checkerboard) and no neighbour's match moved by a cell reaches it, so it asks the
// index itself.
TEST(DetailTransfer, CellsBeyondTheWindowsReachStillFindAMatch) {
  const ptm::Ptm p = SmoothPtm(48, 9);
  const PtmSample sample(p);
  cv::Mat band;
  const DetailDictionary dictionary(sample, 0, band);
  TrianglePatch square = PatchCorrectedToward(p, cv::Size(12, 12), {36, 36}, {36, 36});
  dictionary.Transfer(square, 0);
  ExpectSourcesFrom(square, {36, 36});
  ExpectSourcesAreWindowCentres(square);
  // The last column's cells sit at x = 47: their best window centre is at x = 46.
  EXPECT_NEAR(square.detail_source.at<cv::Vec2f>(5, 11)[0], 46.0f, 1e-3);
  TrianglePatch row = PatchCorrectedToward(p, cv::Size(12, 1), {36, 20}, {36, 20});
  dictionary.Transfer(row, 0);
  ExpectSourcesAreWindowCentres(row);
}

// A sample narrower than a window's reach has no dictionary to transfer from.
TEST(DetailTransfer, ASampleNarrowerThanAWindowIsNotUsable) {
  const ptm::Ptm p = SmoothPtm(4, 7);
  const PtmSample sample(p);
  cv::Mat band;
  EXPECT_FALSE(DetailDictionary(sample, 0, band).Usable());
}

}  // namespace
}  // namespace texlume::synth
