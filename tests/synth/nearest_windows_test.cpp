#include "synth/nearest_windows.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

namespace texlume::synth {
namespace {

// Windows like detail transfer's: 3 x 3 points 2 texels apart on 6 smooth planes
// (blurred noise), one window per texel inside (detail transfer pads each point
// to 8 floats with zeros, which change no distance).
cv::Mat SmoothWindows(int size, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  std::vector<cv::Mat> planes(6);
  for (cv::Mat& p : planes) {
    p.create(size, size, CV_32FC1);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) p.at<float>(y, x) = n(rng);
    cv::GaussianBlur(p, p, cv::Size(), 2.0);
  }
  cv::Mat windows;
  for (int y = 2; y < size - 2; ++y)
    for (int x = 2; x < size - 2; ++x) {
      cv::Mat row(1, 54, CV_32FC1);
      float* w = row.ptr<float>();
      for (int b = -1; b <= 1; ++b)
        for (int a = -1; a <= 1; ++a)
          for (const cv::Mat& p : planes) *w++ = p.at<float>(y + 2 * b, x + 2 * a);
      windows.push_back(row);
    }
  return windows;
}

float SquaredDistance(const cv::Mat& a, const cv::Mat& b) {
  return static_cast<float>(cv::norm(a, b, cv::NORM_L2SQR));
}

TEST(NearestWindows, FewComponentsFindTheWindowsThemselves) {
  const cv::Mat windows = SmoothWindows(120, 3);
  const NearestWindows::WindowMatrix source(windows.clone());
  const NearestWindows nearest(source, NearestWindows::Options{});
  EXPECT_GE(nearest.Components(), 1);
  EXPECT_EQ(nearest.Components(), 8);
  cv::Mat queries;
  for (int r = 0; r < windows.rows; r += 37) queries.push_back(windows.row(r));
  std::vector<int> index;
  std::vector<float> distance;
  nearest.Nearest(queries, index, distance);
  for (int q = 0; q < queries.rows; ++q)
    EXPECT_EQ(distance[static_cast<std::size_t>(q)], 0.0f) << q;
}

// Noisy copies of windows: how often the nearest found is the exact nearest, and
// how far the found are on average (their full distance over the exact nearest's).
void ExpectNearlyTheExactNearest(NearestWindows::Options options, double exact_share,
                                 double mean_ratio) {
  const cv::Mat windows = SmoothWindows(120, 5);
  const NearestWindows::WindowMatrix source(windows.clone());
  const NearestWindows nearest(source, options);
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  cv::Mat queries;
  for (int r = 0; r < windows.rows; r += 53) {
    cv::Mat q = windows.row(r).clone();
    for (int i = 0; i < q.cols; ++i) q.at<float>(0, i) += noise(rng);
    queries.push_back(q);
  }
  std::vector<int> index;
  std::vector<float> distance;
  nearest.Nearest(queries, index, distance);
  int exact = 0;
  double ratio_sum = 0.0;
  for (int q = 0; q < queries.rows; ++q) {
    float best = std::numeric_limits<float>::max();
    for (int w = 0; w < windows.rows; ++w)
      best = std::min(best, SquaredDistance(queries.row(q), windows.row(w)));
    const std::size_t n = static_cast<std::size_t>(q);
    // The distance returned is the full one to the window returned.
    EXPECT_NEAR(distance[n], SquaredDistance(queries.row(q), windows.row(index[n])),
                1e-4f * (1.0f + distance[n]));
    EXPECT_GE(distance[n], best * (1.0f - 1e-5f));
    exact += distance[n] <= best * (1.0f + 1e-5f);
    ratio_sum += distance[n] / best;
  }
  EXPECT_GE(exact, exact_share * queries.rows) << exact << " of " << queries.rows;
  EXPECT_LT(ratio_sum / queries.rows, mean_ratio);
}

// Four candidates at eps 4: nearly always the exact nearest.
TEST(NearestWindows, NoisyQueriesFindNearlyTheExactNearestAtTheirFullDistance) {
  ExpectNearlyTheExactNearest(NearestWindows::Options{4, 4.0f}, 0.9, 1.05);
}

// The defaults (one candidate at eps 8) seed detail transfer's propagation: mostly
// the exact nearest, and near it otherwise (218 of 254 and 1.13 when written).
TEST(NearestWindows, TheDefaultsFindMostlyTheExactNearest) {
  ExpectNearlyTheExactNearest(NearestWindows::Options{}, 0.8, 1.2);
}

TEST(NearestWindows, TheSameWindowsGiveTheSameMatches) {
  const cv::Mat windows = SmoothWindows(80, 7);
  const cv::Mat queries = SmoothWindows(20, 8);
  std::vector<int> a, b;
  std::vector<float> da, db;
  const NearestWindows::WindowMatrix source(windows);
  NearestWindows(source, NearestWindows::Options{}).Nearest(queries, a, da);
  NearestWindows(source, NearestWindows::Options{}).Nearest(queries, b, db);
  EXPECT_EQ(a, b);
  EXPECT_EQ(da, db);
}

// Windows made as the index asks for them, whose distance stops once past the
// bound (as detail transfer's dictionaries read theirs from the sample).
class WindowsMadeOnRequest : public NearestWindows::Windows {
 public:
  explicit WindowsMadeOnRequest(cv::Mat all) : all_(std::move(all)) {}
  int Count() const override { return all_.rows; }
  int Length() const override { return all_.cols; }
  void Rows(int first, cv::Mat& block) const override {
    ++runs_asked;
    all_.rowRange(first, first + block.rows).copyTo(block);
  }
  float SquaredDistance(const float* query, int window, float bound) const override {
    const float* w = all_.ptr<float>(window);
    float d = 0.0f;
    int i = 0;
    for (; i < all_.cols && d < bound; ++i) d += (w[i] - query[i]) * (w[i] - query[i]);
    stopped_early += i < all_.cols;
    return d;
  }
  mutable int runs_asked = 0, stopped_early = 0;

 private:
  cv::Mat all_;
};

TEST(NearestWindows, WindowsMadeOnRequestMatchAsTheMatrixOfThem) {
  const cv::Mat windows = SmoothWindows(100, 11);
  cv::Mat queries = SmoothWindows(30, 12);
  const NearestWindows::WindowMatrix matrix(windows.clone());
  const WindowsMadeOnRequest made(windows.clone());
  // Four candidates: the later ones are often rejected by a partial distance.
  const NearestWindows::Options options{4, 4.0f};
  std::vector<int> from_matrix, from_made;
  std::vector<float> d_matrix, d_made;
  NearestWindows(matrix, options).Nearest(queries, from_matrix, d_matrix);
  NearestWindows(made, options).Nearest(queries, from_made, d_made);
  EXPECT_EQ(from_made, from_matrix);
  EXPECT_EQ(d_made, d_matrix);
  // The index read the windows through the source, and candidates were rejected
  // on partial distances.
  EXPECT_GT(made.runs_asked, 1);
  EXPECT_GT(made.stopped_early, 0);
}

}  // namespace
}  // namespace texlume::synth
