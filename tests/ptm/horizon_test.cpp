// Horizon mapping: normals integrate to the relief they came from, and a wall's
// horizon and shadow fall where its geometry puts them.
#include "ptm/horizon.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "core/errors.h"
#include "ptm/exr_io.h"
#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// Unit normals of the height field H(x, y) = a x + b y (texel frame, y up).
std::vector<float> PlaneNormals(int width, int height, double a, double b) {
  const Eigen::Vector3d n = Eigen::Vector3d(-a, -b, 1.0).normalized();
  std::vector<float> normals;
  for (int i = 0; i < width * height; ++i)
    for (int k = 0; k < 3; ++k) normals.push_back(static_cast<float>(n[k]));
  return normals;
}

TEST(HeightFromNormals, APlanesNormalsIntegrateToThePlaneOnEvenAndOddSizes) {
  for (const auto& [width, height] : {std::pair{16, 12}, std::pair{7, 5}}) {
    const double a = 0.3, b = -0.2;
    const cv::Mat h = HeightFromNormals(PlaneNormals(width, height, a, b), width, height);
    ASSERT_EQ(h.cols, width);
    ASSERT_EQ(h.rows, height);
    EXPECT_NEAR(cv::mean(h)[0], 0.0, 1e-9);
    // Rows run down, so y = -row.
    for (int r = 0; r < height; ++r)
      for (int c = 0; c + 1 < width; ++c) {
        EXPECT_NEAR(h.at<double>(r, c + 1) - h.at<double>(r, c), a, 2e-4) << width;
        if (r + 1 < height) {
          EXPECT_NEAR(h.at<double>(r + 1, c) - h.at<double>(r, c), -b, 2e-4);
        }
      }
  }
}

TEST(HeightFromNormals, RefusesMismatchedSizes) {
  EXPECT_THROW(HeightFromNormals(PlaneNormals(4, 4, 0, 0), 4, 5), std::invalid_argument);
  EXPECT_THROW(HeightFromNormals(PlaneNormals(1, 4, 0, 0), 1, 4), std::invalid_argument);
}

// A wall 10 texels high from column 20 on: seen from column 10 it rises 45 degrees
// towards +x and not at all towards -x.
TEST(HorizonMap, AWallsHorizonAndShadowFollowItsGeometry) {
  cv::Mat h = cv::Mat::zeros(8, 40, CV_64FC1);
  h(cv::Rect(20, 0, 20, 8)).setTo(10.0);
  const HorizonMap horizon = ComputeHorizonMap(h, 8, 32);
  const std::size_t texel = 4 * 40 + 10;
  EXPECT_NEAR(horizon.ElevationAt(texel, 0.0), 45.0 * kDegree, 1e-6);
  EXPECT_NEAR(horizon.ElevationAt(texel, std::numbers::pi), 0.0, 1e-9);
  // Half-way between sectors 0 and 1 (0 and 45 degrees of azimuth): the mean.
  const double diagonal = horizon.ElevationAt(texel, 45.0 * kDegree);
  EXPECT_NEAR(horizon.ElevationAt(texel, 22.5 * kDegree), 0.5 * (45.0 * kDegree + diagonal), 1e-6);
  // Out of reach: a wall 25 texels away is beyond a 16-texel search.
  EXPECT_NEAR(ComputeHorizonMap(h, 8, 16).ElevationAt(4 * 40 + 0, 0.0), 0.0, 1e-9);
  // On top of the wall nothing rises.
  EXPECT_NEAR(horizon.ElevationAt(4 * 40 + 25, 0.0), 0.0, 1e-9);
  // y is up the image: a ridge along the top rows rises towards +y (azimuth 90
  // degrees), not towards -y.
  cv::Mat ridge = cv::Mat::zeros(40, 8, CV_64FC1);
  ridge(cv::Rect(0, 0, 8, 20)).setTo(10.0);
  const HorizonMap up = ComputeHorizonMap(ridge, 8, 32);
  const std::size_t below = 29 * 8 + 4;  // 10 rows below the ridge's edge (row 19)
  EXPECT_NEAR(up.ElevationAt(below, 90.0 * kDegree), 45.0 * kDegree, 1e-6);
  EXPECT_NEAR(up.ElevationAt(below, -90.0 * kDegree), 0.0, 1e-9);

  const auto light = [](double elevation_deg, double azimuth_deg) {
    const double e = elevation_deg * kDegree, a = azimuth_deg * kDegree;
    return Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  };
  const double penumbra = 4.0 * kDegree;
  EXPECT_EQ(HorizonVisibility(horizon, texel, light(30, 0), penumbra), 0.0);
  EXPECT_EQ(HorizonVisibility(horizon, texel, light(60, 0), penumbra), 1.0);
  EXPECT_NEAR(HorizonVisibility(horizon, texel, light(45, 0), penumbra), 0.5, 1e-6);
  EXPECT_EQ(HorizonVisibility(horizon, texel, light(10, 180), penumbra), 1.0);
}

TEST(HorizonMap, ARaySeesNothingBeyondItsRegion) {
  // The wall of the test above, 10 texels away: in another region it casts no
  // horizon, in the texel's own region (or for a texel of region -1) the same 45
  // degrees as without regions.
  cv::Mat h = cv::Mat::zeros(8, 40, CV_64FC1);
  h(cv::Rect(20, 0, 20, 8)).setTo(10.0);
  cv::Mat regions(h.size(), CV_32SC1, cv::Scalar(0));
  regions(cv::Rect(15, 0, 25, 8)).setTo(1);
  const std::size_t texel = 4 * 40 + 10;
  EXPECT_NEAR(ComputeHorizonMap(h, 8, 32, regions).ElevationAt(texel, 0.0), 0.0, 1e-9);
  regions(cv::Rect(0, 0, 40, 8)).setTo(1);
  EXPECT_NEAR(ComputeHorizonMap(h, 8, 32, regions).ElevationAt(texel, 0.0), 45.0 * kDegree, 1e-6);
  regions(cv::Rect(0, 0, 15, 8)).setTo(-1);
  EXPECT_NEAR(ComputeHorizonMap(h, 8, 32, regions).ElevationAt(texel, 0.0), 45.0 * kDegree, 1e-6);
  // A gutter (-1) between the texel and the wall, the wall in the texel's own region
  // again: the ray stops at the gutter, as at another chart.
  regions.setTo(0);
  regions(cv::Rect(14, 0, 2, 8)).setTo(-1);
  EXPECT_NEAR(ComputeHorizonMap(h, 8, 32, regions).ElevationAt(texel, 0.0), 0.0, 1e-9);
  // Diagonally (sector 1, 45 degrees up the image) a ray stops likewise at the region's edge.
  cv::Mat hill = cv::Mat::zeros(40, 40, CV_64FC1);
  hill(cv::Rect(20, 0, 20, 20)).setTo(10.0);
  cv::Mat quadrants(hill.size(), CV_32SC1, cv::Scalar(0));
  const std::size_t corner = 30 * 40 + 10;  // row 30, column 10: the hill up and right
  EXPECT_GT(ComputeHorizonMap(hill, 8, 32, quadrants).ElevationAt(corner, 45.0 * kDegree), 0.1);
  quadrants(cv::Rect(20, 0, 20, 20)).setTo(1);
  EXPECT_NEAR(ComputeHorizonMap(hill, 8, 32, quadrants).ElevationAt(corner, 45.0 * kDegree), 0.0,
              1e-9);
  EXPECT_THROW(ComputeHorizonMap(h, 8, 32, cv::Mat(4, 4, CV_32SC1, cv::Scalar(0))),
               std::invalid_argument);
  EXPECT_THROW(ComputeHorizonMap(h, 8, 32, cv::Mat(h.size(), CV_8UC1, cv::Scalar(0))),
               std::invalid_argument);
}

TEST(HorizonMap, RefusesSettingsOutOfRange) {
  const cv::Mat h = cv::Mat::zeros(4, 4, CV_64FC1);
  EXPECT_THROW(ComputeHorizonMap(h, 3, 8), std::invalid_argument);
  EXPECT_THROW(ComputeHorizonMap(h, 8, 0), std::invalid_argument);
  EXPECT_THROW(ComputeHorizonMap(cv::Mat::zeros(4, 4, CV_32FC1), 8, 8), std::invalid_argument);
}

TEST(SelfShadowingExr, RoundTripsAndRefusesFilesThatAreNotHorizons) {
  cv::Mat h = cv::Mat::zeros(6, 10, CV_64FC1);
  h(cv::Rect(5, 0, 5, 6)).setTo(3.0);
  SelfShadowing shadowing;
  shadowing.horizon = ComputeHorizonMap(h, 8, 16);
  shadowing.height_scale = 1.75;
  shadowing.shadow_floor = 0.25;
  shadowing.penumbra_rad = 4.0 * kDegree;
  testing::TempDir dir;
  const std::filesystem::path file = dir.path() / "horizon.exr";
  WriteSelfShadowingExr(shadowing, file);
  const SelfShadowing back = ReadSelfShadowingExr(file);
  EXPECT_EQ(back.horizon.width, 10);
  EXPECT_EQ(back.horizon.height, 6);
  EXPECT_EQ(back.horizon.sectors, 8);
  EXPECT_EQ(back.horizon.elevation_rad, shadowing.horizon.elevation_rad);
  EXPECT_FLOAT_EQ(static_cast<float>(back.height_scale), 1.75f);
  EXPECT_FLOAT_EQ(static_cast<float>(back.shadow_floor), 0.25f);
  EXPECT_FLOAT_EQ(static_cast<float>(back.penumbra_rad), static_cast<float>(4.0 * kDegree));
  // The light factor: the floor in full shadow, 1 in full light.
  const Eigen::Vector3d low(std::cos(10 * kDegree), 0.0, std::sin(10 * kDegree));
  EXPECT_NEAR(back.LightFactor(3 * 10 + 3, low), 0.25, 1e-6);
  EXPECT_NEAR(back.LightFactor(3 * 10 + 3, Eigen::Vector3d::UnitZ()), 1.0, 1e-6);

  // Sector channels without the attributes, and an elevation beyond the zenith.
  std::vector<cv::Mat> planes(8, cv::Mat(4, 4, CV_32FC1, cv::Scalar(0.1f)));
  std::vector<std::string> names;
  for (int s = 0; s < 8; ++s) names.push_back("horizon.0" + std::to_string(s));
  WriteExr(dir.path() / "bare.exr", planes, names);
  EXPECT_THROW(ReadSelfShadowingExr(dir.path() / "bare.exr"), InputError);
  planes[3] = cv::Mat(4, 4, CV_32FC1, cv::Scalar(2.0f));
  WriteExr(dir.path() / "steep.exr", planes, names,
           {{"texlume:height_scale", 1.f},
            {"texlume:shadow_floor", 0.2f},
            {"texlume:penumbra_rad", 0.07f}});
  EXPECT_THROW(ReadSelfShadowingExr(dir.path() / "steep.exr"), InputError);
  names[2] = "R";
  WriteExr(dir.path() / "other.exr", planes, names);
  EXPECT_THROW(ReadSelfShadowingExr(dir.path() / "other.exr"), InputError);
}

// A relief of bumps (texel units), 64 x 64.
cv::Mat Bumps(double amplitude) {
  cv::Mat h(64, 64, CV_64FC1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      h.at<double>(y, x) = amplitude * std::sin(0.4 * x) * std::sin(0.3 * y + 0.2 * x);
  return h;
}

// A horizon of heights times m is that of the heights with its tangents times m, so an
// atlas integrated half as steep as its sample is given the sample's relief back.
TEST(LowLightShadowLoss, MatchingAFlatterReliefScalesItBackToTheSamples) {
  SelfShadowing sample, atlas;
  sample.shadow_floor = atlas.shadow_floor = 0.3;
  sample.penumbra_rad = atlas.penumbra_rad = 4.0 * std::numbers::pi / 180.0;
  sample.horizon = ComputeHorizonMap(Bumps(4.0), 16, 48);
  atlas.horizon = ComputeHorizonMap(Bumps(2.0), 16, 48);
  const double target = LowLightShadowLoss(sample, {});
  const double flatter = LowLightShadowLoss(atlas, {});
  ASSERT_GT(target, 0.05);
  ASSERT_LT(flatter, 0.8 * target);
  EXPECT_NEAR(LowLightShadowLoss(atlas, {}, 2.0), target, 0.01 * target);
  const double gain = MatchLowLightShadowLoss(atlas, {}, target);
  EXPECT_NEAR(gain, 2.0, 0.05);
  EXPECT_NEAR(atlas.height_scale, gain, 1e-12);
  EXPECT_NEAR(LowLightShadowLoss(atlas, {}), target, 0.002);
  double worst = 0.0;
  for (std::size_t i = 0; i < sample.horizon.elevation_rad.size(); ++i)
    worst = std::max(worst, std::abs(static_cast<double>(atlas.horizon.elevation_rad[i]) -
                                     sample.horizon.elevation_rad[i]));
  EXPECT_LT(worst, 0.02);  // radians
  // Only the texels counted: those behind no horizon lose nothing.
  std::vector<char> open(sample.horizon.NumTexels(), 1);
  for (std::size_t t = 0; t < open.size(); ++t)
    for (int k = 0; k < 16; ++k)
      if (sample.horizon.elevation_rad[t * 16 + static_cast<std::size_t>(k)] > 0.0f) open[t] = 0;
  ASSERT_GT(std::count(open.begin(), open.end(), 1), 0);
  EXPECT_EQ(LowLightShadowLoss(sample, open), 0.0);
  // A target out of reach is met as far as the gain's range allows.
  SelfShadowing faint = sample;
  faint.horizon = ComputeHorizonMap(Bumps(0.4), 16, 48);
  ASSERT_GT(LowLightShadowLoss(faint, {}, 4.0), 0.0);
  ASSERT_LT(LowLightShadowLoss(faint, {}, 4.0), target);
  EXPECT_NEAR(MatchLowLightShadowLoss(faint, {}, target), 4.0, 1e-6);
  // A flat map, or a target of no shadow, leaves the relief as it is.
  SelfShadowing flat = atlas;
  flat.horizon = ComputeHorizonMap(cv::Mat::zeros(64, 64, CV_64FC1), 16, 48);
  EXPECT_EQ(MatchLowLightShadowLoss(flat, {}, target), 1.0);
  EXPECT_EQ(LowLightShadowLoss(flat, {}), 0.0);
  SelfShadowing again = sample;
  EXPECT_EQ(MatchLowLightShadowLoss(again, {}, 0.0), 1.0);
  EXPECT_EQ(again.horizon.elevation_rad, sample.horizon.elevation_rad);
  // A horizon at a float's pi / 2 (the reader's largest) stays a horizon when scaled.
  SelfShadowing steep = sample;
  steep.horizon.elevation_rad[0] = static_cast<float>(std::numbers::pi / 2);
  ScaleRelief(steep, 2.0);
  EXPECT_GE(steep.horizon.elevation_rad[0], 1.5f);
  EXPECT_LE(steep.horizon.elevation_rad[0], static_cast<float>(std::numbers::pi / 2));
}

}  // namespace
}  // namespace texlume::ptm
