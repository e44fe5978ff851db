#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "render/fidelity.h"

namespace texlume::render {

/// PSNR (dB, peak 1) and SSIM (Gaussian window 11, sigma 1.5, on each channel,
/// averaged) of two CV_32FC3 images over the pixels where `mask` (CV_8UC1) is set.
double MaskedPsnr(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);
double MaskedSsim(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

/// A rendered view against its ground truth, inside a mask; also reduced by an
/// integer factor (area averaging; the mask nearest) when it is over 1.
struct ViewMetrics {
  std::string name;
  double psnr = 0, ssim = 0, psnr_reduced = 0, ssim_reduced = 0;
  /// Luma bias, chroma spread, gradient and spectrum against the truth, at full
  /// resolution.
  FidelityMetrics fidelity;
};

/// Measures `rendered` against `truth` (CV_32FC3 display RGB, one size) inside
/// `inside` (CV_8UC1), at full resolution and, for `reduced_factor` > 1,
/// reduced by it; and its appearance (FidelityMetrics) at full resolution.
ViewMetrics MeasureView(const std::string& name, const cv::Mat& rendered, const cv::Mat& truth,
                        const cv::Mat& inside, int reduced_factor);

/// Every figure of `views` averaged (per band too); named "mean". Zeros when empty.
ViewMetrics MeanViewMetrics(const std::vector<ViewMetrics>& views);

}  // namespace texlume::render
