#include "render/metrics.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace texlume::render {

double MaskedPsnr(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  double sum = 0.0;
  std::size_t count = 0;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x) {
      if (!mask.at<std::uint8_t>(y, x)) continue;
      const cv::Vec3f d = a.at<cv::Vec3f>(y, x) - b.at<cv::Vec3f>(y, x);
      sum += d.dot(d);
      count += 3;
    }
  if (count == 0) return 0.0;
  const double mse = sum / static_cast<double>(count);
  return mse <= 1e-20 ? 200.0 : 10.0 * std::log10(1.0 / mse);
}

double MaskedSsim(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  auto blur = [](const cv::Mat& m) {
    cv::Mat out;
    cv::GaussianBlur(m, out, cv::Size(11, 11), 1.5);
    return out;
  };
  const cv::Mat mu_a = blur(a), mu_b = blur(b);
  const cv::Mat aa = blur(a.mul(a)) - mu_a.mul(mu_a), bb = blur(b.mul(b)) - mu_b.mul(mu_b);
  const cv::Mat ab = blur(a.mul(b)) - mu_a.mul(mu_b);
  cv::Mat n1 = 2 * mu_a.mul(mu_b), n2 = 2 * ab, d1 = mu_a.mul(mu_a) + mu_b.mul(mu_b), d2 = aa + bb;
  cv::add(n1, cv::Scalar::all(c1), n1);
  cv::add(n2, cv::Scalar::all(c2), n2);
  cv::add(d1, cv::Scalar::all(c1), d1);
  cv::add(d2, cv::Scalar::all(c2), d2);
  const cv::Mat numerator = n1.mul(n2), denominator = d1.mul(d2);
  cv::Mat map;
  cv::divide(numerator, denominator, map);
  const cv::Scalar s = cv::mean(map, mask);
  return (s[0] + s[1] + s[2]) / 3.0;
}

ViewMetrics MeasureView(const std::string& name, const cv::Mat& rendered, const cv::Mat& truth,
                        const cv::Mat& inside, int reduced_factor) {
  ViewMetrics m;
  m.name = name;
  m.psnr = MaskedPsnr(rendered, truth, inside);
  m.ssim = MaskedSsim(rendered, truth, inside);
  m.fidelity =
      CompareAppearance(MeasureAppearance(rendered, inside), MeasureAppearance(truth, inside));
  if (reduced_factor > 1) {
    const cv::Size small(truth.cols / reduced_factor, truth.rows / reduced_factor);
    cv::Mat a, b, mk;
    cv::resize(rendered, a, small, 0, 0, cv::INTER_AREA);
    cv::resize(truth, b, small, 0, 0, cv::INTER_AREA);
    cv::resize(inside, mk, small, 0, 0, cv::INTER_NEAREST);
    m.psnr_reduced = MaskedPsnr(a, b, mk);
    m.ssim_reduced = MaskedSsim(a, b, mk);
  }
  return m;
}

ViewMetrics MeanViewMetrics(const std::vector<ViewMetrics>& views) {
  ViewMetrics mean;
  mean.name = "mean";
  const double n = static_cast<double>(views.size());
  FidelityMetrics& f = mean.fidelity;
  for (const ViewMetrics& m : views) {
    mean.psnr += m.psnr / n;
    mean.ssim += m.ssim / n;
    mean.psnr_reduced += m.psnr_reduced / n;
    mean.ssim_reduced += m.ssim_reduced / n;
    f.luma_bias += m.fidelity.luma_bias / n;
    f.linear_luma_bias += m.fidelity.linear_luma_bias / n;
    f.chroma_spread_ratio += m.fidelity.chroma_spread_ratio / n;
    f.gradient_histogram_distance += m.fidelity.gradient_histogram_distance / n;
    f.gradient_p90 += m.fidelity.gradient_p90 / n;
    f.gradient_p90_truth += m.fidelity.gradient_p90_truth / n;
    f.power_spectrum_db += m.fidelity.power_spectrum_db / n;
    for (std::size_t b = 0; b < f.band_power_db.size() && b < m.fidelity.band_power_db.size(); ++b)
      f.band_power_db[b] += m.fidelity.band_power_db[b] / n;
  }
  return mean;
}

}  // namespace texlume::render
