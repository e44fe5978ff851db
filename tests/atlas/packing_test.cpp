#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <random>

#include "atlas/atlas.h"
#include "atlas/chart_packing.h"
#include "core/errors.h"
#include "mesh/triangle_frame.h"

namespace texlume::atlas {
namespace {

TEST(PackSkyline, RectanglesDoNotOverlapAndStayInTheirBins) {
  std::mt19937 rng(2);
  std::vector<std::pair<int, int>> sizes;
  std::uniform_int_distribution<int> side(3, 60);
  for (int i = 0; i < 300; ++i) {
    // Drawn one at a time, last first: a call's arguments are evaluated in an
    // unspecified order (GCC right to left, clang left to right).
    const int height = side(rng), width = side(rng);
    sizes.emplace_back(width, height);
  }
  const auto placed = PackSkyline(sizes, 256, 256);
  int bins = 0;
  for (const auto& p : placed) bins = std::max(bins, p[0] + 1);
  std::vector<cv::Mat> used(static_cast<std::size_t>(bins));
  for (cv::Mat& m : used) m = cv::Mat::zeros(256, 256, CV_8UC1);
  long area = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const auto [bin, x, y] = placed[i];
    ASSERT_GE(x, 0);
    ASSERT_GE(y, 0);
    ASSERT_LE(x + sizes[i].first, 256);
    ASSERT_LE(y + sizes[i].second, 256);
    cv::Mat roi =
        used[static_cast<std::size_t>(bin)](cv::Rect(x, y, sizes[i].first, sizes[i].second));
    ASSERT_EQ(cv::countNonZero(roi), 0) << "rectangle " << i << " overlaps";
    roi.setTo(1);
    area += sizes[i].first * sizes[i].second;
  }
  EXPECT_GT(static_cast<double>(area) / (bins * 256.0 * 256.0), 0.6);  // skyline packs tightly
  EXPECT_THROW(PackSkyline({{300, 10}}, 256, 256), OptionError);
}

// A strip of random triangles laid side by side (texel units: t = 1), as a chart.
struct RandomStrip {
  std::vector<synth::TrianglePatch> patches;
  std::vector<ChartFace> chart;
};
RandomStrip MakeRandomStrip(int faces, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RandomStrip s;
  for (int f = 0; f < faces; ++f) {
    synth::TrianglePatch patch;
    const double z = u(rng), y = u(rng), x = u(rng), w = u(rng);
    patch.corners_in_frame = {Eigen::Vector2d(0, 0), Eigen::Vector2d(4 + 12 * w, 0),
                              Eigen::Vector2d(12 * x - 2, 3 + 10 * y)};
    ChartFace cf;
    cf.face = f;
    cf.linear = Eigen::Rotation2Dd(6.28 * z).toRotationMatrix();
    cf.translation = Eigen::Vector2d(9.3 * f, 0.37 * f);
    s.patches.push_back(patch);
    s.chart.push_back(cf);
  }
  return s;
}

// The outline's texels as a mask on the grid of its own box.
cv::Mat OutlineMask(const chart_packing::ChartOutline& o) {
  cv::Mat mask = cv::Mat::zeros(o.Height(), o.Width(), CV_8UC1);
  for (const auto& r : o.runs) mask(cv::Rect(r.x, r.row, r.length, 1)).setTo(1);
  return mask;
}

TEST(ChartOutline, HoldsExactlyTheTexelsWithinReachAndIsTheUnionOfItsFaces) {
  const RandomStrip strip = MakeRandomStrip(40, 3);
  const int gutter = 2;
  const double reach = gutter + 0.5 + 1e-6;
  for (const double angle : {0.0, 3.14159265358979}) {
    const chart_packing::ChartOutline o =
        chart_packing::Outline(strip.chart, angle, strip.patches, 1.0, gutter);
    // Brute force: every texel centre of the box tested against every face.
    std::vector<std::array<Eigen::Vector2d, 3>> corners;
    chart_packing::Box(strip.chart, angle, strip.patches, 1.0, gutter, &corners);
    cv::Mat expected = cv::Mat::zeros(o.Height(), o.Width(), CV_8UC1);
    for (auto c : corners) {
      for (auto& p : c) p = Eigen::Vector2d(p.x() - o.lo.x(), o.hi.y() - p.y());
      for (int y = 0; y < o.Height(); ++y)
        for (int x = 0; x < o.Width(); ++x)
          if (mesh::WithinReachOfTriangle(c, Eigen::Vector2d(x + 0.5, y + 0.5), reach))
            expected.at<std::uint8_t>(y, x) = 1;
    }
    const cv::Mat mask = OutlineMask(o);
    EXPECT_EQ(cv::countNonZero(mask != expected), 0);
    EXPECT_EQ(o.area, cv::countNonZero(expected));

    // Any piece of the strip: the union of its faces' outlines is its outline.
    std::vector<chart_packing::ChartOutline> face_outlines;
    for (const ChartFace& cf : strip.chart)
      face_outlines.push_back(chart_packing::Outline({cf}, angle, strip.patches, 1.0, gutter));
    for (const auto& [first, last] : {std::pair{0, 40}, std::pair{5, 17}, std::pair{39, 40}}) {
      const std::vector<ChartFace> piece(strip.chart.begin() + first, strip.chart.begin() + last);
      std::vector<const chart_packing::ChartOutline*> faces;
      for (int f = first; f < last; ++f)
        faces.push_back(&face_outlines[static_cast<std::size_t>(f)]);
      const auto whole = chart_packing::Outline(piece, angle, strip.patches, 1.0, gutter);
      const auto united = chart_packing::UnionOutline(piece, faces, strip.patches, 1.0, gutter);
      EXPECT_EQ(united.lo, whole.lo);
      EXPECT_EQ(united.hi, whole.hi);
      EXPECT_EQ(united.area, whole.area);
      EXPECT_EQ(united.row_first_x, whole.row_first_x);
      EXPECT_EQ(cv::countNonZero(OutlineMask(united) != OutlineMask(whole)), 0);
    }
  }
}

}  // namespace
}  // namespace texlume::atlas
