#include "synth/detail_transfer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "mesh/triangle_frame.h"
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

// Only the wanted cells are matched (here the left half of the grid: the
// correction's place found there, by the index and by propagation within it); the
// others keep their own place in the sample.
TEST(DetailTransfer, OnlyTheWantedCellsAreMatched) {
  const ptm::Ptm p = SmoothPtm(48, 5);
  const PtmSample sample(p);
  cv::Mat band;
  const DetailDictionary dictionary(sample, 0, band);
  const cv::Point at(6, 8), to(25, 4);
  TrianglePatch patch = PatchCorrectedToward(p, cv::Size(12, 12), at, to);
  cv::Mat wanted = cv::Mat::zeros(12, 12, CV_8UC1);
  wanted.colRange(0, 6).setTo(1);
  dictionary.Transfer(patch, 0, wanted);
  for (int j = 1; j + 1 < 12; ++j)
    for (int i = 0; i < 12; ++i) {
      const cv::Vec2f s = patch.detail_source.at<cv::Vec2f>(j, i);
      const cv::Point expected = i < 6 ? to : at;
      if (i == 0) continue;  // the grid's edge: clamped windows
      EXPECT_NEAR(s[0], expected.x + i, 1e-3) << "cell " << i << ", " << j;
      EXPECT_NEAR(s[1], expected.y + j, 1e-3) << "cell " << i << ", " << j;
    }
  // Every cell wanted: the same matches as no mask.
  TrianglePatch all = PatchCorrectedToward(p, cv::Size(12, 12), at, to);
  TrianglePatch unmasked = all;
  dictionary.Transfer(all, 0, cv::Mat::ones(12, 12, CV_8UC1));
  dictionary.Transfer(unmasked, 0);
  EXPECT_EQ(cv::norm(all.detail_source, unmasked.detail_source, cv::NORM_INF), 0.0);
}

// A right triangle's patch (strip of 8 texels) with a correction grid at 0.6 cells
// per texel.
TrianglePatch TrianglePatchWithGrid(double t) {
  TrianglePatch patch;
  patch.corners_in_frame = {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.4, 0.0),
                            Eigen::Vector2d(0.0, 0.3)};
  patch.x_min = -8 * t, patch.y_max = 0.3 + 8 * t;
  patch.width = 56, patch.height = 46;
  patch.correction_density = Eigen::Vector2d(0.6, 0.6);
  patch.correction.assign(6, cv::Mat::zeros(28, 34, CV_32FC1));
  return patch;
}

// Every cell that a texel within the reach of the triangle reads (the 4 cells
// around it on the grid with a weight above 0, clamped at the grid's edges, as
// SamplePtmPatch reads them) is wanted, and the cells far from the triangle are not.
TEST(CellsReadWithin, HoldsEveryCellAReadWithinTheReachTakes) {
  const double t = 0.01, reach = 4.0;
  const TrianglePatch patch = TrianglePatchWithGrid(t);
  EXPECT_TRUE(CellsReadWithin(patch, t, -1.0).empty());
  const cv::Mat wanted = CellsReadWithin(patch, t, reach);
  ASSERT_EQ(wanted.size(), patch.correction[0].size());
  std::array<Eigen::Vector2d, 3> corners;
  for (std::size_t k = 0; k < 3; ++k)
    corners[k] = Eigen::Vector2d((patch.corners_in_frame[k].x() - patch.x_min) / t - 0.5,
                                 (patch.y_max - patch.corners_in_frame[k].y()) / t - 0.5);
  const cv::Size grid = wanted.size();
  int reads = 0;
  for (double v = -0.5; v <= patch.height - 0.5; v += 0.25)
    for (double u = -0.5; u <= patch.width - 0.5; u += 0.25) {
      if (mesh::SignedDistanceToTriangle(corners, Eigen::Vector2d(u, v)) > reach) continue;
      const double gu = std::clamp((u + 0.5) * 0.6 - 0.5, 0.0, grid.width - 1.0);
      const double gv = std::clamp((v + 0.5) * 0.6 - 0.5, 0.0, grid.height - 1.0);
      const int x0 = static_cast<int>(gu), y0 = static_cast<int>(gv);
      for (const int y : {y0, std::min(y0 + 1, grid.height - 1)})
        for (const int x : {x0, std::min(x0 + 1, grid.width - 1)}) {
          const double w = (1.0 - std::abs(gu - x)) * (1.0 - std::abs(gv - y));
          if (w <= 0.0) continue;
          ++reads;
          ASSERT_EQ(wanted.at<std::uint8_t>(y, x), 1)
              << "cell " << x << ", " << y << " read at (" << u << ", " << v << ")";
        }
    }
  EXPECT_GT(reads, 1000);
  // The corner of the patch opposite the right angle lies far from the hypotenuse.
  EXPECT_EQ(wanted.at<std::uint8_t>(0, grid.width - 1), 0);
  EXPECT_LT(cv::countNonZero(wanted), grid.area());
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
