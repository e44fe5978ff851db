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

/// sum_c I_c^2 of a set of planes.
cv::Mat PlaneEnergy(const std::vector<cv::Mat>& planes);

/// The same by nested loops: the reference the tests hold the fast path to.
cv::Mat MaskedSsdBruteForce(const std::vector<cv::Mat>& image_planes,
                            const std::vector<cv::Mat>& template_planes, const cv::Mat& mask);

/// Classic quilting's choice: a position at random (uniform, from `rng`) among
/// those whose error is within (1 + tolerance) of the smallest in `errors`.
cv::Point PickWithinTolerance(const cv::Mat& errors, double tolerance, std::mt19937_64& rng);

}  // namespace texlume::synth
