#pragma once

#include <map>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "synth/template_match.h"

namespace texlume::synth {

/// A face's overlap with its placed neighbours (paper 003, Algorithm 2): the
/// patch texels the neighbours' patches reach across the shared edges, and the
/// feature values they have there.
struct OverlapTexels {
  cv::Size patch;              // the face's patch (texels)
  std::vector<int> texels;     // j * patch.width + i
  std::vector<float> targets;  // the features' values per texel, side by side
  /// The sum of squared differences over the overlap between the targets and the
  /// feature planes with the patch placed at `at` (top left, texels).
  double SumOfSquares(const std::vector<cv::Mat>& features, cv::Point at) const;
};

/// Where a face no photo sees goes in the sample (paper 003): the placement
/// whose feature planes best continue its neighbours over the overlap (the sum
/// of squared differences over the overlap texels), picked at random among
/// those within (1 + tolerance) of the best, as classic quilting picks
/// (PickWithinTolerance).
///
/// Coarse to fine (issue 33), as the photo-constrained search: every placement
/// is scored at a reduced density (the features and the overlap averaged over
/// blocks of 2^h x 2^h texels; FFT), and around the best `kCandidates` of them
/// every placement within half a block is scored again at full density, directly
/// over the overlap texels (the sample mirrored past its right and bottom edges
/// for the coarse grid, so that it reaches the last placements). h is the most halvings (at most
/// kMaxHalvings) that leave the patch kMinCells blocks a side; with none, every placement is scored
/// at full density (FFT).
class OverlapPlacement {
 public:
  static constexpr int kMaxHalvings = 2;
  static constexpr int kMinCells = 6;
  static constexpr int kCandidates = 16;

  /// `features`: the sample's feature planes (CV_32FC1, one size); they must
  /// outlive this object.
  explicit OverlapPlacement(const std::vector<cv::Mat>& features);

  struct Placement {
    cv::Point texel;     // top left in the sample
    double error = 0.0;  // the sum of squared differences over the overlap
  };
  /// The placement of a patch with a non-empty overlap. Not for several threads at
  /// once: the reduced sample's spectra are made on first use.
  Placement Pick(const OverlapTexels& overlap, double tolerance, std::mt19937_64& rng);

  /// The halvings Pick uses for a patch of this size.
  int Halvings(cv::Size patch) const;

 private:
  // The overlap as planes of the patch's size: the targets and a 0/1 mask.
  std::vector<cv::Mat> TargetPlanes(const OverlapTexels& overlap, cv::Mat& mask) const;
  // The features (and spectra) averaged over blocks of 2^halvings texels, once.
  const ImageSpectra& SpectraAt(int halvings);
  // The full-density placements within half a block of the best coarse ones.
  std::vector<cv::Point> Refined(const cv::Mat& coarse_errors, int halvings, cv::Size patch) const;

  const std::vector<cv::Mat>& features_;
  std::map<int, ImageSpectra> spectra_;  // by halvings
};

}  // namespace texlume::synth
