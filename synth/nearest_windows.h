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
  /// The defaults as measured on the 512 x 512 stone sample and the realistic sphere
  /// (docs/synth.md, "Where the time per triangle goes" and "A coarser seed for
  /// propagation"): 8 components match as well as 12 (6 lose 0.0009 SSIM); one
  /// candidate at eps 8 seeds detail transfer's propagation within 0.0004 SSIM of
  /// four at eps 4, for about 20 % less of detail transfer's matching time.
  struct Options {
    int components = 8;  ///< principal components the tree searches
    int candidates = 1;  ///< nearest in the components, ranked by full distance
    float eps = 8.0f;    ///< approximation of the tree search (0: exact in the components)
  };

  /// Indexes `windows` (CV_32FC1, a window per row, at least 2 rows).
  NearestWindows(cv::Mat windows, Options options);
  ~NearestWindows();
  NearestWindows(const NearestWindows&) = delete;
  NearestWindows& operator=(const NearestWindows&) = delete;

  /// For each row of `queries` (CV_32FC1, the windows' length): the index of the
  /// nearest window found and its full squared distance.
  void Nearest(const cv::Mat& queries, std::vector<int>& index,
               std::vector<float>& squared_distance) const;

  int Components() const { return components_.rows; }

 private:
  cv::Mat Project(const cv::Mat& rows) const;

  Options options_;
  cv::Mat windows_;     // CV_32FC1, full length
  cv::Mat mean_;        // 1 x length
  cv::Mat components_;  // Components() x length, orthonormal rows
  struct Tree;
  std::unique_ptr<Tree> tree_;  // over windows_ in the components
};

}  // namespace texlume::synth
