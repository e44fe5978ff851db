#include "synth/placement_search.h"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <thread>

#include "synth/colour_sample.h"

namespace texlume::synth {
namespace {

// A colour texture with structure at every scale: blurred noise at three widths.
cv::Mat StructuredColour(int size, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  cv::Mat sum = cv::Mat::zeros(size, size, CV_32FC3);
  for (const double sigma : {0.7, 2.0, 5.0}) {
    cv::Mat noise(size, size, CV_32FC3);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const float c2 = n(rng), c1 = n(rng), c0 = n(rng);
        noise.at<cv::Vec3f>(y, x) = cv::Vec3f(c0, c1, c2);
      }
    cv::GaussianBlur(noise, noise, cv::Size(), sigma);
    cv::Scalar mean, stddev;
    cv::meanStdDev(noise, mean, stddev);
    sum += noise * (0.08 / stddev[0]);
  }
  sum += cv::Scalar::all(0.5);
  cv::Mat clamped;
  cv::min(cv::max(sum, 0.02), 0.98, clamped);
  return clamped;
}

constexpr int kPatch = 24;

// A view at density `level` whose photo is the sample relit at the placement `at`
// (sample texels), plus Gaussian noise of `noise` (linear).
RectifiedView PlantedView(const ColourSample& sample, int level, cv::Point at,
                          const FaceLighting& lighting, double gain, double noise, unsigned seed) {
  RectifiedView v;
  v.level = level;
  v.lighting = lighting;
  const ReducedPlanes& r = sample.Reduced(level);
  const cv::Size grid(static_cast<int>(std::lround(kPatch * r.rx)),
                      static_cast<int>(std::lround(kPatch * r.ry)));
  const cv::Rect cells(cv::Point(static_cast<int>(std::lround(at.x * r.rx)),
                                 static_cast<int>(std::lround(at.y * r.ry))),
                       grid);
  v.planes = sample.Relight(r.Window(cells), lighting, gain);
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, static_cast<float>(noise));
  for (cv::Mat& plane : v.planes) {
    plane = plane.clone();
    for (int y = 0; y < plane.rows; ++y)
      for (int x = 0; x < plane.cols; ++x) plane.at<float>(y, x) += n(rng);
  }
  // A triangle's mask, as a face's views have: the cells above the diagonal are
  // outside it (their photo values are not the face's).
  v.mask = cv::Mat::zeros(grid, CV_32FC1);
  for (int y = 0; y < grid.height; ++y)
    for (int x = 0; x < grid.width; ++x)
      if (x * grid.height <= (y + 1) * grid.width) v.mask.at<float>(y, x) = 1.0f;
  for (cv::Mat& plane : v.planes) plane.setTo(5.0f, v.mask == 0);
  v.count = cv::sum(v.mask)[0];
  return v;
}

struct Fixture {
  ColourSample sample;
  std::vector<double> gains{1.0, 0.8};
  cv::Point planted;
  std::vector<RectifiedView> views;
  // By default a 160 x 160 sample, planted off every coarse grid.
  explicit Fixture(double noise, const cv::Mat& colour = StructuredColour(160, 7),
                   cv::Point planted_at = {73, 41})
      : sample(colour), planted(planted_at) {
    const FaceLighting zenith{Eigen::Vector3d::UnitZ(), {{Eigen::Vector3d::UnitZ(), 1.0}}, {}};
    const FaceLighting slanted{
        Eigen::Vector3d::UnitZ(), {{Eigen::Vector3d(0.6, 0.0, 0.8), 1.5}}, {}};
    views.push_back(PlantedView(sample, 0, planted, zenith, gains[0], noise, 1));
    views.push_back(PlantedView(sample, 4, planted, slanted, gains[1], noise, 2));
    views.back().photo = 1;
  }
};

// Both searches find the planted placement, and score it as the photos' noise.
TEST(PlacementSearch, BothSearchesFindThePlantedPlacement) {
  const Fixture f(0.01);
  const PlacementSearch search(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  ASSERT_GE(search.CoarseSteps(3, 6), 1);
  const std::vector<ScoredPlacement> exhaustive = search.Exhaustive(12);
  const std::vector<ScoredPlacement> coarse_to_fine = search.CoarseToFine(12, 16);
  ASSERT_EQ(exhaustive.size(), 12u);
  ASSERT_EQ(coarse_to_fine.size(), 12u);
  EXPECT_EQ(exhaustive[0].second, f.planted);
  EXPECT_EQ(coarse_to_fine[0].second, f.planted);
  // The noise of each photo (0.01, linear) in eq. 3's RMS, summed over 2 views.
  EXPECT_NEAR(coarse_to_fine[0].first, 0.02, 0.004);
  for (std::size_t n = 1; n < coarse_to_fine.size(); ++n)
    EXPECT_LE(coarse_to_fine[n - 1].first, coarse_to_fine[n].first);
  for (const auto& [score, at] : coarse_to_fine) EXPECT_TRUE(std::isfinite(score)) << at;
}

// The direct scores of the refinement equal the FFT scores of the exhaustive
// search at the same placements.
TEST(PlacementSearch, RefinedScoresEqualTheExhaustiveScores) {
  const Fixture f(0.05);
  const PlacementSearch search(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  std::map<std::pair<int, int>, float> everywhere;
  for (const auto& [score, at] : search.Exhaustive(1 << 20)) everywhere[{at.x, at.y}] = score;
  const std::vector<ScoredPlacement> refined = search.CoarseToFine(12, 16);
  ASSERT_EQ(refined.size(), 12u);
  for (const auto& [score, at] : refined) {
    ASSERT_TRUE(everywhere.count({at.x, at.y})) << at;
    EXPECT_NEAR(score, everywhere.at({at.x, at.y}), 1e-4 + 1e-4 * score) << at;
  }
  // No coarser density: the same as the exhaustive search.
  EXPECT_EQ(search.CoarseSteps(3, 1000), 0);
  const std::vector<ScoredPlacement> fallback = search.CoarseToFine(12, 16, 3, 1000);
  const std::vector<ScoredPlacement> exhaustive = search.Exhaustive(12);
  for (std::size_t n = 0; n < 12; ++n) EXPECT_EQ(fallback[n], exhaustive[n]);
}

// Eq. 3 at a placement summed as the search's direct scores sum it, one placement
// alone: per view, a row's masked squared differences in floats (channels, then
// cells, in order), the rows in doubles; the views' RMS differences summed in order.
float PlacementAlone(const Fixture& f, cv::Point texel) {
  double total = 0.0;
  for (const RectifiedView& v : f.views) {
    const ReducedPlanes& r = f.sample.Reduced(v.level);
    const std::vector<cv::Mat> relit = f.sample.Relight(r, v.lighting, f.gains[v.photo]);
    const cv::Point at(
        std::min(static_cast<int>(std::lround(texel.x * r.rx)), relit[0].cols - v.mask.cols),
        std::min(static_cast<int>(std::lround(texel.y * r.ry)), relit[0].rows - v.mask.rows));
    double ssd = 0.0;
    for (int j = 0; j < v.mask.rows; ++j) {
      float row = 0.0f;
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < v.mask.cols; ++i) {
          const float d = relit[static_cast<std::size_t>(c)].at<float>(at.y + j, at.x + i) -
                          v.planes[static_cast<std::size_t>(c)].at<float>(j, i);
          row += v.mask.at<float>(j, i) * d * d;
        }
      ssd += row;
    }
    total += std::sqrt(std::max(ssd, 0.0) / (3.0 * v.count));
  }
  return static_cast<float>(total);
}

// Each refined score against PlacementAlone: to the bit, unless the library was built
// to fuse multiplies and adds (-march=native with FMA; these tests are built at -O1,
// where GCC fuses none).
void ExpectScoresAsAlone(const Fixture& f, const std::vector<ScoredPlacement>& refined) {
  for (const auto& [score, at] : refined) {
#ifdef __FMA__
    EXPECT_NEAR(score, PlacementAlone(f, at), 1e-6f * (1.0f + score)) << at;
#else
    EXPECT_EQ(score, PlacementAlone(f, at)) << at;
#endif
  }
}

// Every placement of the exhaustive search against PlacementAlone: the grid is summed
// by FFT for the photos' density (a 160 x 160 sample) and directly for the coarser
// view (80 x 80, where that takes fewer operations), whose 69 placements a row end
// in lanes past the last one.
TEST(PlacementSearch, EveryExhaustiveScoreIsThePlacementsOwn) {
  const Fixture f(0.05);
  const PlacementSearch search(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  const std::vector<ScoredPlacement> everywhere = search.Exhaustive(1 << 20);
  ASSERT_EQ(everywhere.size(), static_cast<std::size_t>(137 * 137));
  for (const auto& [score, at] : everywhere)
    ASSERT_NEAR(score, PlacementAlone(f, at), 1e-4 + 1e-4 * score) << at;
}

// The direct scores are computed for several neighbouring placements side by side;
// each is still its own placement's sum, to the bit.
TEST(PlacementSearch, PlacementsScoredSideBySideScoreAsAlone) {
  const Fixture f(0.05);
  const PlacementSearch search(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  const std::vector<ScoredPlacement> refined = search.CoarseToFine(12, 16);
  ASSERT_EQ(refined.size(), 12u);
  ExpectScoresAsAlone(f, refined);
}

// A sample barely wider than a patch (a few placements a row, fewer than the lanes
// past some of them): the candidates' neighbourhoods span whole rows, and a lane past
// a row's last placement must not stand for the next row's first.
TEST(PlacementSearch, PlacementsScoredSideBySideAtTheSamplesEdges) {
  const Fixture f(0.05, StructuredColour(640, 7).colRange(0, kPatch + 6).clone(), {3, 301});
  const PlacementSearch search(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  // One coarser step: with more, refining would cost more than the exhaustive search.
  ASSERT_GE(search.CoarseSteps(1, 6), 1);
  const std::vector<ScoredPlacement> refined = search.CoarseToFine(40, 40, 1, 6);
  ASSERT_EQ(refined.size(), 40u);
  EXPECT_EQ(refined[0].second, f.planted);
  ExpectScoresAsAlone(f, refined);
}

// A lent scratch, left holding another search's relit cells of other sizes (a
// larger sample, one view more; then NaN everywhere), changes no score: each
// face's search relights every cell it reads.
TEST(PlacementSearch, ALentScratchScoresAsTheSearchsOwn) {
  const Fixture f(0.05);
  const ColourSample larger(StructuredColour(224, 11));
  std::vector<RectifiedView> other = f.views;
  other.push_back(f.views.front());
  RelitScratch scratch;
  const PlacementSearch before(larger, other, f.gains, cv::Size(kPatch + 8, kPatch), &scratch);
  ASSERT_EQ(before.CoarseToFine(12, 16).size(), 12u);
  // It refined (the direct scores took the scratch) on the larger sample's cells.
  const std::array<cv::Mat, 3> grown = scratch.Planes(0, cv::Size(5, 7));
  EXPECT_EQ(grown[2].size(), cv::Size(5, 7));
  ASSERT_GE(grown[0].step[0], 224 * sizeof(float));
  for (std::size_t slot = 0; slot < other.size(); ++slot)
    for (cv::Mat plane : scratch.Planes(slot, cv::Size(224, 224)))  // views: the buffers
      plane.setTo(std::numeric_limits<float>::quiet_NaN());
  const PlacementSearch lent(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch), &scratch);
  const PlacementSearch own(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  const std::vector<ScoredPlacement> with_lent = lent.CoarseToFine(12, 16);
  const std::vector<ScoredPlacement> with_own = own.CoarseToFine(12, 16);
  ASSERT_EQ(with_lent.size(), 12u);
  ASSERT_EQ(with_own.size(), 12u);
  for (std::size_t n = 0; n < with_own.size(); ++n) EXPECT_EQ(with_lent[n], with_own[n]);
}

// A sample whose relighting fails under one photo's gain (as a failed allocation
// would): the error leaves the search, whose views are scored on every core,
// as an exception the job reports, not as the end of the process.
class FailingUnderGain : public ColourSample {
 public:
  FailingUnderGain(const cv::Mat& display, double failing_gain)
      : ColourSample(display), failing_gain_(failing_gain) {}
  std::vector<cv::Mat> Relight(const ReducedPlanes& reduced, const FaceLighting& lighting,
                               double gain) const override {
    if (gain == failing_gain_) throw std::runtime_error("relighting failed");
    return ColourSample::Relight(reduced, lighting, gain);
  }

 private:
  double failing_gain_;
};

TEST(PlacementSearch, AnErrorInOneViewLeavesTheSearchAsAnException) {
  const Fixture f(0.01);
  const FailingUnderGain failing(StructuredColour(160, 7), f.gains[1]);
  const PlacementSearch search(failing, f.views, f.gains, cv::Size(kPatch, kPatch));
  EXPECT_THROW(search.Exhaustive(12), std::runtime_error);
  EXPECT_THROW(search.CoarseToFine(12, 16), std::runtime_error);
}

// The relit windows are the whole relit sample's cells, clipped at its borders.
TEST(PlacementSearch, RelitWindowsAreTheRelitSamplesCells) {
  const Fixture f(0.0);
  const PlacementSearch search(f.sample, f.views, f.gains, cv::Size(kPatch, kPatch));
  for (const cv::Point at : {cv::Point(72, 40), cv::Point(0, 0), cv::Point(136, 136)}) {
    const std::vector<RelitWindow> relit = search.RelitAround(at, {3, 2});
    ASSERT_EQ(relit.size(), 2u);
    for (std::size_t v = 0; v < 2; ++v) {
      const ReducedPlanes& r = f.sample.Reduced(f.views[v].level);
      const std::vector<cv::Mat> whole =
          f.sample.Relight(r, f.views[v].lighting, f.gains[f.views[v].photo]);
      const cv::Rect window(relit[v].origin, relit[v].planes[0].size());
      EXPECT_EQ(window, (window & cv::Rect(cv::Point(0, 0), whole[0].size())));
      const int m = v == 0 ? 3 : 2;
      const cv::Point cell(static_cast<int>(std::lround(at.x * r.rx)),
                           static_cast<int>(std::lround(at.y * r.ry)));
      EXPECT_EQ(window.x, std::max(0, cell.x - m));
      EXPECT_EQ(window.br().x, std::min(whole[0].cols, cell.x + f.views[v].mask.cols + m));
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(cv::norm(relit[v].planes[static_cast<std::size_t>(c)],
                           whole[static_cast<std::size_t>(c)](window), cv::NORM_INF),
                  0.0);
    }
  }
}

// Faces searched on several threads ask for the sample's levels at once: each
// level is reduced once, every thread gets the same planes, and they are the
// planes reduced on one thread.
TEST(MaterialSample, LevelsAskedOnSeveralThreadsAreReducedOnce) {
  const ColourSample sample(StructuredColour(96, 5));
  constexpr int kLevels = 6, kThreads = 4;
  std::vector<std::array<const ReducedPlanes*, kLevels>> got(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int n = 0; n < kLevels; ++n) {
        const int level = (n + t) % kLevels;  // each thread in another order
        got[static_cast<std::size_t>(t)][static_cast<std::size_t>(level)] = &sample.Reduced(level);
      }
    });
  for (std::thread& thread : threads) thread.join();
  const ColourSample alone(StructuredColour(96, 5));
  for (int level = 0; level < kLevels; ++level) {
    const auto l = static_cast<std::size_t>(level);
    for (int t = 1; t < kThreads; ++t) EXPECT_EQ(got[static_cast<std::size_t>(t)][l], got[0][l]);
    const ReducedPlanes& expected = alone.Reduced(level);
    ASSERT_EQ(got[0][l]->planes.size(), expected.planes.size());
    EXPECT_EQ(got[0][l]->rx, expected.rx);
    for (std::size_t c = 0; c < expected.planes.size(); ++c)
      EXPECT_EQ(cv::norm(got[0][l]->planes[c], expected.planes[c], cv::NORM_INF), 0.0);
  }
}

// A colour sample whose first reduction waits (up to 10 s) until another level was
// returned to another thread; it counts the reductions.
class FirstReductionWaits : public ColourSample {
 public:
  using ColourSample::ColourSample;
  void OtherLevelReturned() const {
    {
      const std::lock_guard lock(mutex_);
      other_returned_ = true;
    }
    changed_.notify_all();
  }
  mutable std::atomic<int> reductions{0};
  mutable bool waited_for_other = false;

 protected:
  const std::vector<cv::Mat>& RelightPlanes() const override {
    if (reductions++ == 0) {
      std::unique_lock lock(mutex_);
      waited_for_other =
          changed_.wait_for(lock, std::chrono::seconds(10), [&] { return other_returned_; });
    }
    return ColourSample::RelightPlanes();
  }

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  mutable bool other_returned_ = false;
};

// A level being reduced holds up only the threads that ask for that level.
TEST(MaterialSample, ALevelBeingReducedDoesNotHoldUpAnother) {
  const FirstReductionWaits sample(StructuredColour(64, 3));
  std::thread first([&] { sample.Reduced(0); });
  while (sample.reductions.load() == 0) std::this_thread::yield();
  sample.Reduced(4);  // while level 0 is being reduced
  sample.OtherLevelReturned();
  first.join();
  EXPECT_TRUE(sample.waited_for_other);
  sample.Reduced(0), sample.Reduced(4);
  EXPECT_EQ(sample.reductions.load(), 2);
}

}  // namespace
}  // namespace texlume::synth
