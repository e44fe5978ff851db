#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <random>

#include "atlas/atlas.h"
#include "atlas/chart_packing.h"
#include "atlas/packing_bin.h"
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

// True when no texel of `outline` (CV_8UC1) put at (x, y) meets a used texel of `used`.
bool FreeAt(const cv::Mat& used, const cv::Mat& outline, int x, int y) {
  for (int r = 0; r < outline.rows; ++r) {
    const uchar* in_outline = outline.ptr<uchar>(r);
    const uchar* in_used = used.ptr<uchar>(y + r) + x;
    for (int c = 0; c < outline.cols; ++c)
      if ((in_outline[c] & in_used[c]) != 0) return false;
  }
  return true;
}

// Brute force: the first position, by rows then columns, where no texel of the
// outline meets a used texel of `used`, its bottom not below `max_bottom`.
std::pair<int, int> FirstFreePosition(const cv::Mat& used, const cv::Mat& outline, int max_bottom) {
  for (int y = 0; y + outline.rows <= std::min(used.rows, max_bottom); ++y)
    for (int x = 0; x + outline.cols <= used.cols; ++x)
      if (FreeAt(used, outline, x, y)) return {x, y};
  return {-1, -1};
}

// Drops the outlines one after another into a bin of `size`, some with a bottom limit,
// each where FirstFit puts it, after checking that against the brute force.
struct Drops {
  int dropped = 0, refused = 0;
};
Drops DropAndCompare(int size, const std::vector<chart_packing::ChartOutline>& outlines) {
  chart_packing::PackingBin bin(size);
  cv::Mat used = cv::Mat::zeros(size, size, CV_8UC1);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> bottom(size / 5, size);
  Drops drops;
  for (std::size_t i = 0; i < outlines.size(); ++i) {
    const chart_packing::ChartOutline& o = outlines[i];
    const cv::Mat mask = OutlineMask(o);
    const int max_bottom = i % 3 == 0 ? bottom(rng) : size;
    const std::pair<int, int> fit = bin.FirstFit(o, chart_packing::LargestSquare(o), max_bottom);
    const std::pair<int, int> expected = FirstFreePosition(used, mask, max_bottom);
    EXPECT_EQ(fit, expected) << "outline " << i;
    if (fit != expected) return drops;
    if (fit.first < 0) {
      ++drops.refused;
      continue;
    }
    bin.Take(o, fit.first, fit.second);
    cv::Mat roi = used(cv::Rect(fit.first, fit.second, o.Width(), o.Height()));
    roi |= mask;
    ++drops.dropped;
    EXPECT_GE(bin.UsedRows(), fit.second + o.Height());
  }
  return drops;
}

// Outlines of 1-3 random triangles at random turns.
std::vector<chart_packing::ChartOutline> RandomOutlines(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> faces(1, 3);
  std::uniform_real_distribution<double> turn(0.0, 6.28);
  std::vector<chart_packing::ChartOutline> outlines;
  for (int i = 0; i < count; ++i) {
    const RandomStrip strip = MakeRandomStrip(faces(rng), seed + static_cast<unsigned>(i));
    outlines.push_back(chart_packing::Outline(strip.chart, turn(rng), strip.patches, 1.0, 1));
  }
  return outlines;
}

TEST(PackingBin, FirstFitIsTheFirstFreePositionInAFragmentedBin) {
  // Small outlines until the bin is full: holes of every size, rows with many free
  // runs. 100 texels: the last block of each row's tree is partial.
  const Drops drops = DropAndCompare(100, RandomOutlines(250, 100));
  EXPECT_GT(drops.dropped, 40);   // the bin filled up...
  EXPECT_GT(drops.refused, 100);  // ...and then refused outlines it had no room for
}

TEST(PackingBin, FirstFitHoldsForOutlinesWithSquaresBeyondTheCap) {
  // Right triangles of 100 texels a side (inside squares of about 50 + gutter) and
  // of 150 (about 75, more than PackingBin::kMaxSquare) among small outlines.
  std::vector<chart_packing::ChartOutline> outlines = RandomOutlines(40, 500);
  for (const double legs : {150.0, 100.0, 150.0}) {
    synth::TrianglePatch patch;
    patch.corners_in_frame = {Eigen::Vector2d(0, 0), Eigen::Vector2d(legs, 0),
                              Eigen::Vector2d(0, legs)};
    ChartFace cf;
    cf.face = 0;
    cf.linear = Eigen::Matrix2d::Identity();
    cf.translation = Eigen::Vector2d::Zero();
    outlines.push_back(chart_packing::Outline({cf}, 0.3 * legs, {patch}, 1.0, 1));
  }
  EXPECT_GT(chart_packing::LargestSquare(outlines.back()).side,
            chart_packing::PackingBin::kMaxSquare);
  for (const auto& o : RandomOutlines(60, 900)) outlines.push_back(o);
  const Drops drops = DropAndCompare(230, outlines);
  EXPECT_GT(drops.dropped, 40);
}

TEST(PackOutlines, AtlasesPassedOverStillTakeSmallChartsInTheirHoles) {
  // Many charts of 3 triangles, then single triangles half as large or less, largest
  // first: the first atlases refuse the large charts long enough to be passed over,
  // and must take small ones again.
  const int size = 64, gutter = 1;
  std::vector<std::vector<chart_packing::ChartOutline>> outlines;
  const unsigned large = 3 * chart_packing::kBinRefusalsToClose;
  for (unsigned i = 0; i < large + chart_packing::kBinRefusalsToClose; ++i) {
    const RandomStrip strip = MakeRandomStrip(i < large ? 3 : 1, i);
    std::vector<chart_packing::ChartOutline> turns;
    for (const double angle : {0.0, 1.5708})
      turns.push_back(chart_packing::Outline(strip.chart, angle, strip.patches, 1.0, gutter));
    outlines.push_back(std::move(turns));
  }
  std::vector<std::size_t> order(outlines.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return outlines[a][0].area > outlines[b][0].area;
  });
  const chart_packing::OutlinePacking packing =
      chart_packing::PackOutlines(outlines, chart_packing::LargestSquares(outlines), order, size,
                                  chart_packing::DropRule::kLowestBottom, nullptr);
  std::vector<cv::Mat> used;
  bool small_in_first_atlas = false;
  for (const std::size_t c : order) {
    const chart_packing::OutlineDrop& d = packing.drops[c];
    while (static_cast<int>(used.size()) <= d.bin) used.push_back(cv::Mat::zeros(size, size, 0));
    const auto& o = outlines[c][static_cast<std::size_t>(d.rotation)];
    ASSERT_TRUE(d.x >= 0 && d.y >= 0 && d.x + o.Width() <= size && d.y + o.Height() <= size);
    cv::Mat roi = used[static_cast<std::size_t>(d.bin)](cv::Rect(d.x, d.y, o.Width(), o.Height()));
    ASSERT_EQ(cv::countNonZero(roi & OutlineMask(o)), 0) << "chart " << c << " overlaps";
    roi |= OutlineMask(o);
    small_in_first_atlas |= c >= large && d.bin == 0;
  }
  EXPECT_GT(used.size(), 8u);
  // A chart no empty atlas takes is an error, not an endless run of new atlases.
  EXPECT_THROW(chart_packing::PackOutlines(
                   {outlines[0]}, chart_packing::LargestSquares({outlines[0]}), {0},
                   outlines[0][0].Width() - 1, chart_packing::DropRule::kLowestBottom, nullptr),
               InternalError);
  EXPECT_GT(packing.bins_passed_over, 0);
  EXPECT_TRUE(small_in_first_atlas);
}

}  // namespace
}  // namespace texlume::atlas
