// How the bake reads a PTM patch out of its sample (SamplePtmPatch, issue 29):
// Catmull-Rom, exact at texel centres, reproducing a quadratic between them with
// the taps past the patch's rectangle reading the sample around it, and clamped
// where the rectangle meets the sample's edge.
#include <gtest/gtest.h>

#include <map>

#include "synth/material_sample.h"

namespace texlume::synth {
namespace {

constexpr double kTexel = 0.5;  // world units per texel

// q(x, y) over sample texels (x right, y down).
double Quadratic(double x, double y) {
  return 0.2 + 0.03 * x + 0.01 * x * x - 0.02 * x * y + 0.015 * y * y;
}

std::vector<cv::Mat> QuadraticPlanes(int width, int height) {
  cv::Mat a(height, width, CV_32FC1), b(height, width, CV_32FC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      a.at<float>(y, x) = static_cast<float>(Quadratic(x, y));
      b.at<float>(y, x) = static_cast<float>(1.0 - 2.0 * Quadratic(x, y));
    }
  return {a, b};
}

TrianglePatch PatchAt(int sample_x, int sample_y, int width, int height) {
  TrianglePatch p;
  p.x_min = 1.0, p.y_max = 2.0;
  p.width = width, p.height = height, p.sample_x = sample_x, p.sample_y = sample_y;
  return p;
}

// The frame point of patch texel position (u, v) (centres at integers).
Eigen::Vector2d FramePoint(const TrianglePatch& p, double u, double v) {
  return {p.x_min + (u + 0.5) * kTexel, p.y_max - (v + 0.5) * kTexel};
}

TEST(SamplePtmPatch, ReadsTheSampleTexelAtEachCentreUpToTheSamplesEdge) {
  const std::vector<cv::Mat> planes = QuadraticPlanes(10, 8);
  const std::map<int, cv::Mat> no_detail;
  // The rectangle's left and bottom sides lie on the sample's edges.
  const TrianglePatch patch = PatchAt(0, 5, 4, 3);
  for (int v = 0; v < patch.height; ++v)
    for (int u = 0; u < patch.width; ++u) {
      float out[2];
      ASSERT_TRUE(SamplePtmPatch(planes, ptm::PtmFormat::kLrgb, no_detail, patch, kTexel,
                                 FramePoint(patch, u, v), out));
      EXPECT_FLOAT_EQ(out[0], planes[0].at<float>(5 + v, u)) << u << ", " << v;
      EXPECT_FLOAT_EQ(out[1], planes[1].at<float>(5 + v, u)) << u << ", " << v;
    }
}

TEST(SamplePtmPatch, ReadsBetweenCentresFromTheSampleAroundTheRectangle) {
  const std::vector<cv::Mat> planes = QuadraticPlanes(12, 10);
  const std::map<int, cv::Mat> no_detail;
  const TrianglePatch patch = PatchAt(3, 2, 5, 4);  // taps past it stay in the sample
  for (const auto& [u, v] :
       {std::pair{0.5, 0.5}, std::pair{0.25, 2.75}, std::pair{3.6, 0.1}, std::pair{2.0, 1.5}}) {
    float out[2];
    ASSERT_TRUE(SamplePtmPatch(planes, ptm::PtmFormat::kLrgb, no_detail, patch, kTexel,
                               FramePoint(patch, u, v), out));
    EXPECT_NEAR(out[0], Quadratic(3 + u, 2 + v), 1e-5) << u << ", " << v;
    EXPECT_NEAR(out[1], 1.0 - 2.0 * Quadratic(3 + u, 2 + v), 1e-5) << u << ", " << v;
  }
  // Outside the rectangle (more than half a texel past it): nothing.
  float out[2];
  EXPECT_FALSE(SamplePtmPatch(planes, ptm::PtmFormat::kLrgb, no_detail, patch, kTexel,
                              FramePoint(patch, -0.75, 1.0), out));
}

}  // namespace
}  // namespace texlume::synth
