#include "render/fidelity.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "core/image_io.h"

namespace texlume::render {
namespace {

// Rec. 709 luma of display RGB (R G B channel order, as the renderer's images).
cv::Mat Luma(const cv::Mat& rgb) {
  cv::Mat luma;
  cv::transform(rgb, luma, cv::Matx13f(0.2126f, 0.7152f, 0.0722f));
  return luma;
}

cv::Mat DecodeSrgb(const cv::Mat& rgb) {
  cv::Mat linear = rgb.clone();
  linear.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) {
    for (int c = 0; c < 3; ++c) p[c] = SrgbToLinear(p[c]);
  });
  return linear;
}

// Gradient magnitude by central differences, inside `inner` (the border pixels
// of the image are left out).
std::vector<float> GradientMagnitudes(const cv::Mat& luma, const cv::Mat& inner) {
  std::vector<float> out;
  for (int y = 1; y + 1 < luma.rows; ++y)
    for (int x = 1; x + 1 < luma.cols; ++x) {
      if (!inner.at<std::uint8_t>(y, x)) continue;
      const float gx = 0.5f * (luma.at<float>(y, x + 1) - luma.at<float>(y, x - 1));
      const float gy = 0.5f * (luma.at<float>(y + 1, x) - luma.at<float>(y - 1, x));
      out.push_back(std::sqrt(gx * gx + gy * gy));
    }
  return out;
}

void MeasureGradients(const cv::Mat& luma, const cv::Mat& inner, AppearanceStats& stats) {
  std::vector<float> magnitudes = GradientMagnitudes(luma, inner);
  stats.gradient_histogram.assign(kGradientBins, 0.0);
  if (magnitudes.empty()) return;
  for (float g : magnitudes) {
    const int bin = std::min(kGradientBins - 1, static_cast<int>(g / kGradientBinWidth));
    stats.gradient_histogram[static_cast<std::size_t>(bin)] += 1.0;
  }
  for (double& h : stats.gradient_histogram) h /= static_cast<double>(magnitudes.size());
  const auto p90 = magnitudes.begin() + static_cast<std::ptrdiff_t>(0.9 * (magnitudes.size() - 1));
  std::nth_element(magnitudes.begin(), p90, magnitudes.end());
  stats.gradient_p90 = *p90;
}

// Edge of log-spaced band i (0..kSpectrumBands) in cycles per pixel: 1/128 .. 1/2.
double BandEdge(int i) { return std::pow(2.0, -7.0 + 6.0 * i / kSpectrumBands); }

// Radially averaged power of the luma, mean removed and tapered by the blurred mask
// so the silhouette does not ring.
void MeasureSpectrum(const cv::Mat& luma, const cv::Mat& inner, AppearanceStats& stats) {
  stats.radial_power.assign(kSpectrumBands, 0.0);
  cv::Mat taper;
  inner.convertTo(taper, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(taper, taper, cv::Size(0, 0), 3.0);
  const double weight = cv::sum(taper)[0];
  if (weight <= 0) return;
  const double mean = cv::sum(luma.mul(taper))[0] / weight;
  cv::Mat signal = (luma - mean).mul(taper);
  cv::Mat padded;
  cv::copyMakeBorder(signal, padded, 0, cv::getOptimalDFTSize(luma.rows) - luma.rows, 0,
                     cv::getOptimalDFTSize(luma.cols) - luma.cols, cv::BORDER_CONSTANT, 0);
  cv::Mat spectrum;
  cv::dft(padded, spectrum, cv::DFT_COMPLEX_OUTPUT);
  std::vector<double> count(kSpectrumBands, 0.0);
  const int h = spectrum.rows, w = spectrum.cols;
  for (int ky = 0; ky < h; ++ky)
    for (int kx = 0; kx < w; ++kx) {
      const double fy = (ky <= h / 2 ? ky : ky - h) / static_cast<double>(h);
      const double fx = (kx <= w / 2 ? kx : kx - w) / static_cast<double>(w);
      const double f = std::hypot(fx, fy);
      if (f < BandEdge(0) || f >= BandEdge(kSpectrumBands)) continue;
      const int band = std::min(
          kSpectrumBands - 1, static_cast<int>(std::log2(f / BandEdge(0)) * kSpectrumBands / 6.0));
      const cv::Vec2f c = spectrum.at<cv::Vec2f>(ky, kx);
      stats.radial_power[static_cast<std::size_t>(band)] += c[0] * c[0] + c[1] * c[1];
      count[static_cast<std::size_t>(band)] += 1.0;
    }
  for (int b = 0; b < kSpectrumBands; ++b)
    if (count[static_cast<std::size_t>(b)] > 0)
      stats.radial_power[static_cast<std::size_t>(b)] /=
          count[static_cast<std::size_t>(b)] * weight;
}

}  // namespace

AppearanceStats MeasureAppearance(const cv::Mat& rgb, const cv::Mat& mask) {
  if (rgb.type() != CV_32FC3) throw std::invalid_argument("MeasureAppearance: not CV_32FC3");
  if (mask.type() != CV_8UC1 || mask.size() != rgb.size())
    throw std::invalid_argument("MeasureAppearance: mask is not CV_8UC1 of the image's size");
  AppearanceStats stats;
  const cv::Mat luma = Luma(rgb);
  const int inside = cv::countNonZero(mask);
  if (inside > 0) {
    stats.mean_luma = cv::mean(luma, mask)[0];
    stats.mean_linear_luma = cv::mean(Luma(DecodeSrgb(rgb)), mask)[0];
    cv::Mat channels[3], high, low;
    cv::split(rgb, channels);
    high = cv::max(cv::max(channels[0], channels[1]), channels[2]);
    low = cv::min(cv::min(channels[0], channels[1]), channels[2]);
    stats.mean_chroma_spread = cv::mean(high - low, mask)[0];
  }
  cv::Mat inner;
  cv::erode(mask, inner, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  MeasureGradients(luma, inner, stats);
  MeasureSpectrum(luma, inner, stats);
  return stats;
}

FidelityMetrics CompareAppearance(const AppearanceStats& rendered, const AppearanceStats& truth) {
  FidelityMetrics m;
  auto relative = [](double a, double b) { return b > 0 ? a / b - 1.0 : 0.0; };
  m.luma_bias = relative(rendered.mean_luma, truth.mean_luma);
  m.linear_luma_bias = relative(rendered.mean_linear_luma, truth.mean_linear_luma);
  m.chroma_spread_ratio = relative(rendered.mean_chroma_spread, truth.mean_chroma_spread);
  // 1-D earth mover's distance: the area between the two cumulative histograms.
  double cdf_rendered = 0, cdf_truth = 0;
  const std::size_t bins =
      std::min(rendered.gradient_histogram.size(), truth.gradient_histogram.size());
  for (std::size_t b = 0; b < bins; ++b) {
    cdf_rendered += rendered.gradient_histogram[b];
    cdf_truth += truth.gradient_histogram[b];
    m.gradient_histogram_distance += std::abs(cdf_rendered - cdf_truth) * kGradientBinWidth;
  }
  m.gradient_p90 = rendered.gradient_p90;
  m.gradient_p90_truth = truth.gradient_p90;
  int bands = 0;
  const std::size_t n = std::min(rendered.radial_power.size(), truth.radial_power.size());
  m.band_power_db.assign(n, 0.0);
  for (std::size_t b = 0; b < n; ++b) {
    if (rendered.radial_power[b] <= 0 || truth.radial_power[b] <= 0) continue;
    m.band_power_db[b] = 10.0 * std::log10(rendered.radial_power[b] / truth.radial_power[b]);
    m.power_spectrum_db += std::abs(m.band_power_db[b]);
    ++bands;
  }
  if (bands > 0) m.power_spectrum_db /= bands;
  return m;
}

}  // namespace texlume::render
