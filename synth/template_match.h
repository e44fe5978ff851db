#pragma once

#include <opencv2/core.hpp>
#include <random>
#include <vector>

namespace texlume::synth {

/// Masked sum of squared differences of a multi-plane template against every
/// placement in a multi-plane image (DESIGN.md: FFT template matching):
///   D(x, y) = sum_c sum_{i,j} M(i,j) (T_c(i,j) - I_c(x+i, y+j))^2
/// expanded as sum_c sum M T_c^2 - 2 sum_c corr(I_c, M T_c) + corr(sum_c I_c^2, M),
/// with OpenCV's (DFT-based) cross-correlation. Planes are CV_32FC1 of one size;
/// the result is CV_32FC1 of size (W - w + 1) x (H - h + 1), clamped at 0.
/// `image_energy` is sum_c I_c^2 (pass the same one for every call on an image).
cv::Mat MaskedSsd(const std::vector<cv::Mat>& image_planes, const cv::Mat& image_energy,
                  const std::vector<cv::Mat>& template_planes, const cv::Mat& mask);

/// The transform size for an image side n: the smallest 2^a, 3 * 2^a or 5 * 2^a
/// at least n. OpenCV's optimal sizes (any 2^a 3^b 5^c) are smaller but can be
/// slower: 375 = 3 * 5^3 transforms 1.7 times slower than 384.
int FastDftSize(int n);

/// An image's planes and their energy transformed once (DFT, CCS packed,
/// zero-padded to FastDftSize of each side), for MaskedSsd against many
/// templates: each match then transforms only the template's planes and mask,
/// sums the correlations in the frequency domain and transforms back once. The
/// padding is at least the image, so placements inside it never wrap.
class ImageSpectra {
 public:
  ImageSpectra() = default;
  /// `energy` is PlaneEnergy(planes).
  ImageSpectra(const std::vector<cv::Mat>& planes, const cv::Mat& energy);
  /// MaskedSsd(planes, energy, template_planes, mask), up to float rounding.
  cv::Mat MaskedSsd(const std::vector<cv::Mat>& template_planes, const cv::Mat& mask) const;
  cv::Size ImageSize() const { return image_; }

 private:
  std::vector<cv::Mat> plane_spectra_;
  cv::Mat energy_spectrum_;
  cv::Size image_, padded_;
};

/// sum_c I_c^2 of a set of planes.
cv::Mat PlaneEnergy(const std::vector<cv::Mat>& planes);

/// The same by nested loops: the reference the tests hold the fast path to.
cv::Mat MaskedSsdBruteForce(const std::vector<cv::Mat>& image_planes,
                            const std::vector<cv::Mat>& template_planes, const cv::Mat& mask);

/// Classic quilting's choice: a position at random (uniform, from `rng`) among
/// those whose error is within (1 + tolerance) of the smallest in `errors`.
cv::Point PickWithinTolerance(const cv::Mat& errors, double tolerance, std::mt19937_64& rng);
/// The same choice among a list of errors: the index chosen.
std::size_t PickWithinTolerance(const std::vector<double>& errors, double tolerance,
                                std::mt19937_64& rng);

}  // namespace texlume::synth
