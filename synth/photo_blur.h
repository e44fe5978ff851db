#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

// How much blurrier each photo is than the sample would look at its density
// (issue 29; docs/synth.md, "Photo blur"). A photo integrates its pixels,
// goes through the lens, demosaicing and JPEG, and is resampled into the face
// frame; the sample reduced to the same density is sharper. A
// photo-consistency pass that compares the two cell by cell takes the sample's
// finest detail for an error and removes it. The pass instead compares the
// photo with the model seen through the photo's blur, a Gaussian of sigma
// cells, which is estimated here from the photos themselves.
//
// The estimate compares band energies, not values: the synthesised texture is
// another instance of the material, not the photo's, so its fine detail does
// not line up with the photo's, but its spectrum does. Per photo, over faces it
// sees fully, the ratio of the fine band's energy to the middle band's
// (difference-of-Gaussians bands) in the photo is matched by the same ratio of
// the sample relit under the same lights, over the same cells, blurred by
// sigma. Noise raises the photo's fine band, so the estimate errs toward less
// blur (a pass that corrects a little too much detail, never one that
// sharpens).

namespace texlume::synth {

/// Energies of a grid in two difference-of-Gaussians bands (cells):
/// fine = X - G(kFineSigma) X, middle = G(kFineSigma) X - G(kMiddleSigma) X,
/// summed over the cells of `mask` whose neighbourhood (kBandSupport cells) is
/// in the mask too; Gaussians normalised over the mask.
struct BandEnergies {
  static constexpr double kFineSigma = 0.6, kMiddleSigma = 1.2;
  static constexpr int kBandSupport = 2;
  double fine = 0.0, middle = 0.0;
  int cells = 0;
};
/// `grid` and `mask` CV_32FC1 of one size; mask > 0 marks the cells.
BandEnergies MeasureBands(const cv::Mat& grid, const cv::Mat& mask);

/// MeasureBands of many grids over one mask: what depends on the mask alone
/// (the inner cells, the Gaussians' normalisations) made once; the same values.
class BandMeter {
 public:
  explicit BandMeter(const cv::Mat& mask);
  BandEnergies Measure(const cv::Mat& grid) const;

 private:
  cv::Mat inner_;   // CV_8UC1: cells whose kBandSupport neighbourhood is in the mask
  cv::Mat weight_;  // CV_32FC1: 1 in the mask, else 0
  cv::Mat fine_weight_, middle_weight_;  // weight_ blurred by each band's sigma
};

/// Gaussian blur of sigma cells (none at 0), normalised over `mask` (> 0).
cv::Mat MaskedGaussian(const cv::Mat& grid, const cv::Mat& mask, double sigma);

/// A photo's blur (sigma in cells of its own density level) in cells of a
/// grid at density level `level`. Level L has 2^(-L/4) cells per texel, so a
/// photo pixel spans s = 2^((own_level - level)/4) cells there: sigma s, and
/// on a finer grid (s > 1) also the pixel's own integration, a box of s cells
/// that the model's reduction to the grid no longer matches (its variance
/// beyond a cell's, (s^2 - 1) / 12). At most kMaxBlurCells.
inline constexpr double kMaxBlurCells = 4.0;
double BlurOnGrid(double sigma_cells, int own_level, int level);

/// Collects band energies per photo and solves for each photo's blur.
class PhotoBlurEstimator {
 public:
  /// Candidate sigmas: 0 to 2 cells by 0.1; the estimate interpolates.
  static constexpr int kCandidates = 21;
  static constexpr double kCandidateStep = 0.1;
  /// Faces per photo it uses (the first seen fully and steeply).
  static constexpr int kFacesPerPhoto = 24;

  explicit PhotoBlurEstimator(std::size_t num_photos);

  /// Whether photo `photo` still wants faces.
  bool Wants(std::size_t photo) const;
  /// One face in photo `photo`: the photo's luminance over the face's cells,
  /// and the sample's relit under the same lights over a window of the same
  /// size (`mask` marks the cells of both).
  void Add(std::size_t photo, const cv::Mat& photo_luminance, const cv::Mat& sample_luminance,
           const cv::Mat& mask);
  /// Per photo, sigma in cells of the photo's own density level (about photo
  /// pixels); 0 for a photo without faces or sharper than the sample.
  std::vector<double> SolvePerPhoto() const;
  /// Per photo, its camera's blur: the median of SolvePerPhoto over the photos
  /// with faces taken by the same camera (`camera_of_photo`, e.g. COLMAP's
  /// camera id). Light the sample's model cannot follow (cast shadows under a
  /// grazing light) sharpens a photo against the relit sample; the median
  /// over a camera's photos does not follow such a photo. 0 for a camera
  /// without faces.
  std::vector<double> SolvePerCamera(const std::vector<std::uint32_t>& camera_of_photo) const;

 private:
  struct PerPhoto {
    int faces = 0;
    double photo_fine = 0.0, photo_middle = 0.0;
    std::array<double, kCandidates> sample_fine{}, sample_middle{};
  };
  std::vector<PerPhoto> photos_;
};

/// The sigma at which the fine-to-middle ratio of the blurred sample,
/// `sample_ratio[k]` at sigma k * step (falling with k), equals `photo_ratio`,
/// linear between candidates; 0 above the first, the last candidate below it.
double SigmaMatchingRatio(double photo_ratio, const std::vector<double>& sample_ratio, double step);

}  // namespace texlume::synth
