#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <random>

#include "atlas/atlas.h"
#include "core/errors.h"

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

}  // namespace
}  // namespace texlume::atlas
