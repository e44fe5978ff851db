#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

// Nearest-window search for detail transfer (synth/detail_transfer.h): of a
// set of windows of equal length (a float row each), the one nearest a query in the
// L2 sense. The windows of a sample's coarse coefficients are smooth, so a few
// principal components carry most of their variance: a kd-tree (nanoflann)
// searches those components (approximately: a branch is left when its squared
// distance is not below 1 / (1 + eps) of the worst kept), and the few nearest found there
// are ranked again by their full distance (issue 33: a randomised kd-forest over
// every component, 8 leaves a query, took a third of the synthesis on a 512 x 512
// sample and found the nearest less often).
namespace texlume::synth {

class NearestWindows {
 public:
  /// The principal components the tree searches, fixed so that the tree's
  /// distances unroll (issue 33). As measured on the 512 x 512 stone sample and the
  /// realistic sphere (docs/synth.md, "Where the time per triangle goes"), 8
  /// components match as well as 12 (6 lose 0.0009 SSIM).
  static constexpr int kComponents = 8;

  /// The defaults as measured there ("A coarser seed for propagation"): one
  /// candidate at eps 8 seeds detail transfer's propagation within 0.0004 SSIM of
  /// four at eps 4, for about 20 % less of detail transfer's matching time.
  struct Options {
    int candidates = 1;  ///< nearest in the components, ranked by full distance
    float eps = 8.0f;    ///< approximation of the tree search (0: exact in the components)
  };

  /// Where the windows come from, so that they need not be held: their count and
  /// length, any run of them as rows, and a query's full distance to one.
  class Windows {
   public:
    virtual ~Windows() = default;
    virtual int Count() const = 0;
    virtual int Length() const = 0;
    /// Windows first, first + 1, ... written into the rows of `block` (CV_32FC1,
    /// Length() wide; possibly a view into a larger matrix: write into its storage,
    /// never reallocate it).
    virtual void Rows(int first, cv::Mat& block) const = 0;
    /// The squared L2 distance from `query` (Length() floats) to window `window`,
    /// or a partial sum of it of at least `bound` (it is only compared with bound).
    virtual float SquaredDistance(const float* query, int window, float bound) const = 0;
  };
  /// Windows held in a matrix (CV_32FC1, a window per row).
  class WindowMatrix : public Windows {
   public:
    /// `windows`: CV_32FC1, a window per row (std::invalid_argument otherwise).
    explicit WindowMatrix(cv::Mat windows);
    int Count() const override { return windows_.rows; }
    int Length() const override { return windows_.cols; }
    void Rows(int first, cv::Mat& block) const override {
      windows_.rowRange(first, first + block.rows).copyTo(block);
    }
    float SquaredDistance(const float* query, int window, float bound) const override;

   private:
    cv::Mat windows_;
  };

  /// Indexes `windows` (at least 2, at least kComponents long), which must outlive this.
  NearestWindows(const Windows& windows, Options options);
  NearestWindows(const Windows&& windows, Options options) = delete;  // would dangle
  ~NearestWindows();
  NearestWindows(const NearestWindows&) = delete;
  NearestWindows& operator=(const NearestWindows&) = delete;

  /// For each row of `queries` (CV_32FC1, the windows' length): the index of the
  /// nearest window found and its full squared distance (Windows::SquaredDistance).
  void Nearest(const cv::Mat& queries, std::vector<int>& index,
               std::vector<float>& squared_distance) const;

  int Components() const { return components_.rows; }

 private:
  // The windows' or the queries' principal components, a row each.
  cv::Mat Project(const Windows& rows) const;

  Options options_;
  const Windows& windows_;
  cv::Mat mean_;        // 1 x length
  cv::Mat components_;  // Components() x length, orthonormal rows
  struct Tree;
  std::unique_ptr<Tree> tree_;  // over windows_ in the components
};

}  // namespace texlume::synth
