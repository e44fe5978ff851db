#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace texlume::render {

/// Appearance statistics of one image inside a mask (issue 29): what a viewer
/// notices besides the per-pixel error. Images are CV_32FC3 display (sRGB)
/// values in [0, 1]; luma is Rec. 709's Y' = 0.2126 R + 0.7152 G + 0.0722 B.
struct AppearanceStats {
  double mean_luma = 0;
  /// Mean luma of the linear values (sRGB decoded): the light the image carries,
  /// which a display-luma mean weighs by the sRGB curve.
  double mean_linear_luma = 0;
  /// Mean of max(R, G, B) - min(R, G, B): how coloured the image is.
  double mean_chroma_spread = 0;
  /// Normalised histogram of the luma gradient magnitude (central differences,
  /// luma per pixel) inside the mask eroded by 2 pixels; kGradientBins bins of
  /// kGradientBinWidth, the last one holding everything above.
  std::vector<double> gradient_histogram;
  double gradient_p90 = 0;  ///< 90th percentile of the gradient magnitude
  /// Radially averaged power spectrum of the luma (mean removed, tapered by the
  /// blurred mask), in log-spaced frequency bands from 1/128 to 1/2 cycles per
  /// pixel (kSpectrumBands of them).
  std::vector<double> radial_power;
};

inline constexpr int kGradientBins = 64;
inline constexpr double kGradientBinWidth = 0.0025;  ///< luma per pixel
inline constexpr int kSpectrumBands = 12;

/// Throws std::invalid_argument when the image is not CV_32FC3 or the mask
/// (CV_8UC1, non-zero = inside) is not of its size. An empty mask gives zeros.
AppearanceStats MeasureAppearance(const cv::Mat& rgb, const cv::Mat& mask);

/// A rendering's appearance against its truth's.
struct FidelityMetrics {
  /// mean luma / truth's - 1 (0.01 = 1 % too bright).
  double luma_bias = 0;
  /// The same of the linear luma: a rendering with the truth's light but less
  /// fine contrast has a linear bias near 0 and a positive display bias (the
  /// sRGB curve is concave, so it lifts the mean of a smoother image).
  double linear_luma_bias = 0;
  /// mean chroma spread / truth's - 1 (0.1 = 10 % more colourful).
  double chroma_spread_ratio = 0;
  /// Earth mover's distance between the gradient histograms, luma per pixel:
  /// how far the edge strengths are apart (0 = the same distribution).
  double gradient_histogram_distance = 0;
  /// 90th percentile of the gradient magnitude, rendering and truth.
  double gradient_p90 = 0, gradient_p90_truth = 0;
  /// Mean over the bands of |10 log10(power / truth's power)|, dB.
  double power_spectrum_db = 0;
  /// Per band (kSpectrumBands), the signed 10 log10(power / truth's power), dB
  /// (0 where either has no power).
  std::vector<double> band_power_db = std::vector<double>(kSpectrumBands, 0.0);
};

FidelityMetrics CompareAppearance(const AppearanceStats& rendered, const AppearanceStats& truth);

}  // namespace texlume::render
