#include "model/web_model.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

namespace texlume::model {
namespace {

TEST(QuantisePlane, ConstantPlanesAndExtremesAreExact) {
  const QuantisedPlane constant = QuantisePlane({0.25f, 0.25f});
  EXPECT_EQ(constant.bias, 0.25f);
  EXPECT_EQ(constant.bytes[0], 0);
  const QuantisedPlane q = QuantisePlane({-1.0f, 0.5f, 3.0f});
  EXPECT_EQ(q.bytes[0], 0);
  EXPECT_EQ(q.bytes[2], 255);
  EXPECT_NEAR(q.bytes[1] / 255.0 * q.scale + q.bias, 0.5, 0.5 * q.scale / 255.0);
}

TEST(AtlasChartRegions, LabelsEachChartsTexelsAndLeavesTheRestOut) {
  // A square of two faces whose shared edge has the same texture coordinates on both
  // sides (one chart) and a third face apart (another chart), on a 32 x 16 atlas.
  TexturedModel model;
  model.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {3, 0, 0}};
  model.mesh.faces = {{0, 1, 2}, {0, 2, 3}, {4, 5, 2}};
  model.corner_px = {{Eigen::Vector2f(1, 13), Eigen::Vector2f(13, 13), Eigen::Vector2f(13, 1)},
                     {Eigen::Vector2f(1, 13), Eigen::Vector2f(13, 1), Eigen::Vector2f(1, 1)},
                     {Eigen::Vector2f(17, 13), Eigen::Vector2f(29, 13), Eigen::Vector2f(29, 1)}};
  model.face_atlas = {0, 0, 0};
  model.atlases.emplace_back().Resize(ptm::PtmFormat::kLrgb, 32, 16);
  const std::vector<int> chart = ChartsOfModel(model);
  ASSERT_EQ(chart[0], chart[1]);
  ASSERT_NE(chart[0], chart[2]);
  const std::vector<cv::Mat> regions = AtlasChartRegions(model);
  ASSERT_EQ(regions.size(), 1u);
  ASSERT_EQ(regions[0].size(), cv::Size(32, 16));
  ASSERT_EQ(regions[0].type(), CV_32SC1);
  EXPECT_EQ(regions[0].at<int>(10, 10), chart[0]);  // below the diagonal: face 0
  EXPECT_EQ(regions[0].at<int>(3, 3), chart[0]);    // above it: face 1
  EXPECT_EQ(regions[0].at<int>(10, 26), chart[2]);
  EXPECT_EQ(regions[0].at<int>(3, 20), -1);  // beside face 2's slanted edge
  EXPECT_EQ(regions[0].at<int>(14, 7), -1);  // the gutter below the square
  EXPECT_EQ(regions[0].at<int>(8, 15), -1);  // between the charts
  // The square's 12 x 12 texels and face 2's half of them, with at most the row and
  // column the edges touch (fillConvexPoly's edges are inclusive).
  const int square = cv::countNonZero(regions[0] == chart[0]);
  const int half = cv::countNonZero(regions[0] == chart[2]);
  EXPECT_GE(square, 144);
  EXPECT_LE(square, 169);
  EXPECT_GE(half, 78);
  EXPECT_LE(half, 91);
}

}  // namespace
}  // namespace texlume::model
