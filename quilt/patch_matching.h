#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <list>
#include <opencv2/core.hpp>
#include <vector>

#include "synth/material_sample.h"
#include "synth/template_match.h"

// Entire-patch matching of graph-cut quilting on surfaces (paper 004 §III-B,
// "Patch Matching", after Kwatra et al. 2003): the whole sample, turned to the
// work patch's mean field orientation (one of 72 rotations), is placed over the
// work image where its features differ least from the synthesised part; the
// SSD is normalised by the overlap area and computed with FFTs.

namespace texlume::quilt {

/// One rotated copy of the sample: the largest axis-aligned square that every
/// rotation keeps inside the sample (side floor(min(W, H) / sqrt 2)), turned by
/// `angle_rad` counter-clockwise (x right, y up), its features turned with it.
struct RotatedCopy {
  int rotation = 0;
  double angle_rad = 0;
  std::vector<cv::Mat> planes;  ///< CV_32FC1 feature planes, side x side
  cv::Mat energy;               ///< their summed squares
  /// The planes' and the energy's DFTs, made once per copy: a match then
  /// transforms only the work image.
  synth::ImageSpectra spectra;

  int side() const { return planes.empty() ? 0 : planes[0].cols; }
};

/// The sample's rotated copies, made on first use and kept up to a budget (the
/// paper precomputes all 72; a 512^2 RGB PTM's would take 0.7 GB).
class RotatedSample {
 public:
  static constexpr int kRotations = 72;  ///< paper 004 §III-B

  RotatedSample(const synth::MaterialSample& sample, std::size_t cached_copies = 8);

  /// Side of every copy (texels). Throws InputError when the sample is too small.
  int side() const { return side_; }
  /// The rotation nearest to an angle (radians, counter-clockwise).
  static int RotationNearest(double angle_rad);
  static double AngleOf(int rotation);
  const RotatedCopy& Copy(int rotation);
  /// The sample position (texels, x right, y down, centres at +0.5) that a
  /// copy's point (same convention) shows.
  Eigen::Vector2d SamplePosition(int rotation, const Eigen::Vector2d& copy_px) const;
  /// Planes of the sample's size (CV_32FC1: the sample relit, say) turned as
  /// the copy `rotation` turns the sample (bilinear; values, not features:
  /// nothing in them is turned).
  std::vector<cv::Mat> TurnPlanes(int rotation, const std::vector<cv::Mat>& sample_planes) const;

 private:
  RotatedCopy Make(int rotation) const;

  const synth::MaterialSample& sample_;
  std::size_t budget_;
  int side_ = 0;
  std::list<RotatedCopy> cache_;  ///< most recently used first
};

/// Where the copy goes over the work image: the work image's texel (0, 0) lies
/// on the copy's texel (x, y).
struct Placement {
  int rotation = 0;
  int x = 0, y = 0;
  double cost = 0;         ///< SSD over the synthesised texels / their number
  bool by_photos = false;  ///< chosen among an image term's best (PatchImageTerm)
};

/// The placement of `copy` that best matches the work image's synthesised
/// texels (mask CV_32FC1, 1 synthesised, 0 not; work planes in the copy's
/// feature space, a frame with x right and y up). The work image must fit in
/// the copy. Ties go to the first in raster order.
Placement MatchEntirePatch(const RotatedCopy& copy, const std::vector<cv::Mat>& work_planes,
                           const cv::Mat& work_mask);
/// The cost MatchEntirePatch minimises at every placement of `copy` (the SSD
/// over the synthesised texels over their number): CV_32FC1 of
/// (side - width + 1) x (side - height + 1), placement (x, y) at column x, row y.
cv::Mat EntirePatchCosts(const RotatedCopy& copy, const std::vector<cv::Mat>& work_planes,
                         const cv::Mat& work_mask);
/// The same by nested loops (the reference of tests and the bench).
Placement MatchEntirePatchBruteForce(const RotatedCopy& copy,
                                     const std::vector<cv::Mat>& work_planes,
                                     const cv::Mat& work_mask);

}  // namespace texlume::quilt
