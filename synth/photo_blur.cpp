#include "synth/photo_blur.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace texlume::synth {

namespace {

// The weight of MaskedGaussian's mask: 1 where mask > 0, else 0.
cv::Mat MaskWeight(const cv::Mat& mask) {
  cv::Mat weight;
  cv::Mat(mask > 0).convertTo(weight, CV_32FC1, 1.0 / 255.0);
  return weight;
}

cv::Mat BlurredWeight(const cv::Mat& weight, double sigma) {
  cv::Mat blurred;
  cv::GaussianBlur(weight, blurred, cv::Size(), sigma, sigma, cv::BORDER_CONSTANT);
  return blurred;
}

// The grid blurred over the weight, divided by the weight's blur where that is
// above 1e-6; the grid itself elsewhere.
cv::Mat NormalisedBlur(const cv::Mat& grid, const cv::Mat& weight, double sigma,
                       const cv::Mat& blurred_weight) {
  cv::Mat blurred;
  cv::GaussianBlur(grid.mul(weight), blurred, cv::Size(), sigma, sigma, cv::BORDER_CONSTANT);
  cv::Mat out = grid.clone(), quotient;
  cv::divide(blurred, blurred_weight, quotient);
  quotient.copyTo(out, blurred_weight > 1e-6f);
  return out;
}

}  // namespace

cv::Mat MaskedGaussian(const cv::Mat& grid, const cv::Mat& mask, double sigma) {
  if (sigma <= 0.0) return grid.clone();
  const cv::Mat weight = MaskWeight(mask);
  return NormalisedBlur(grid, weight, sigma, BlurredWeight(weight, sigma));
}

BandMeter::BandMeter(const cv::Mat& mask)
    : weight_(MaskWeight(mask)),
      fine_weight_(BlurredWeight(weight_, BandEnergies::kFineSigma)),
      middle_weight_(BlurredWeight(weight_, BandEnergies::kMiddleSigma)) {
  TEXLUME_CHECK(mask.type() == CV_32FC1, "BandMeter: a one-channel float mask");
  const int k = 2 * BandEnergies::kBandSupport + 1;
  cv::erode(mask > 0, inner_, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)),
            cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
}

BandEnergies BandMeter::Measure(const cv::Mat& grid) const {
  TEXLUME_CHECK(grid.type() == CV_32FC1 && grid.size() == weight_.size(),
                "BandMeter: a one-channel float grid of the mask's size");
  BandEnergies e;
  const cv::Mat fine_low = NormalisedBlur(grid, weight_, BandEnergies::kFineSigma, fine_weight_);
  const cv::Mat middle_low =
      NormalisedBlur(grid, weight_, BandEnergies::kMiddleSigma, middle_weight_);
  for (int j = 0; j < grid.rows; ++j)
    for (int i = 0; i < grid.cols; ++i) {
      if (!inner_.at<std::uint8_t>(j, i)) continue;
      const double fine = grid.at<float>(j, i) - fine_low.at<float>(j, i);
      const double middle = fine_low.at<float>(j, i) - middle_low.at<float>(j, i);
      e.fine += fine * fine;
      e.middle += middle * middle;
      ++e.cells;
    }
  return e;
}

BandEnergies MeasureBands(const cv::Mat& grid, const cv::Mat& mask) {
  return BandMeter(mask).Measure(grid);  // which checks both
}

double BlurOnGrid(double sigma_cells, int own_level, int level) {
  const double span = std::pow(2.0, (own_level - level) / 4.0);
  const double pixel_variance = span > 1.0 ? (span * span - 1.0) / 12.0 : 0.0;
  const double sigma = sigma_cells * span;
  return std::min(kMaxBlurCells, std::sqrt(sigma * sigma + pixel_variance));
}

PhotoBlurEstimator::PhotoBlurEstimator(std::size_t num_photos) : photos_(num_photos) {}

bool PhotoBlurEstimator::Wants(std::size_t photo) const {
  return photo < photos_.size() && photos_[photo].faces < kFacesPerPhoto;
}

void PhotoBlurEstimator::Add(std::size_t photo, const cv::Mat& photo_luminance,
                             const cv::Mat& sample_luminance, const cv::Mat& mask) {
  TEXLUME_CHECK(photo < photos_.size(), "PhotoBlurEstimator: photo index out of range");
  const BandMeter meter(mask);
  const BandEnergies seen = meter.Measure(photo_luminance);
  if (seen.cells == 0) return;
  PerPhoto& p = photos_[photo];
  ++p.faces;
  p.photo_fine += seen.fine;
  p.photo_middle += seen.middle;
  // The sample blurred over the whole window (no mask: its cells around the
  // face are as real as those inside), measured over the face's cells.
  const cv::Mat everywhere = cv::Mat::ones(mask.size(), CV_32FC1);
  for (int k = 0; k < kCandidates; ++k) {
    const cv::Mat blurred = MaskedGaussian(sample_luminance, everywhere, k * kCandidateStep);
    const BandEnergies e = meter.Measure(blurred);
    p.sample_fine[static_cast<std::size_t>(k)] += e.fine;
    p.sample_middle[static_cast<std::size_t>(k)] += e.middle;
  }
}

double SigmaMatchingRatio(double photo_ratio, const std::vector<double>& sample_ratio,
                          double step) {
  if (sample_ratio.empty() || !(photo_ratio < sample_ratio.front())) return 0.0;
  for (std::size_t k = 1; k < sample_ratio.size(); ++k) {
    const double above = sample_ratio[k - 1], below = sample_ratio[k];
    if (photo_ratio < below) continue;
    const double t = above > below ? (above - photo_ratio) / (above - below) : 0.0;
    return (static_cast<double>(k - 1) + t) * step;
  }
  return static_cast<double>(sample_ratio.size() - 1) * step;
}

std::vector<double> PhotoBlurEstimator::SolvePerPhoto() const {
  std::vector<double> sigma(photos_.size(), 0.0);
  for (std::size_t n = 0; n < photos_.size(); ++n) {
    const PerPhoto& p = photos_[n];
    if (p.faces == 0 || !(p.photo_middle > 0.0)) continue;
    std::vector<double> sample_ratio(kCandidates);
    bool ok = true;
    for (std::size_t k = 0; k < sample_ratio.size(); ++k) {
      ok = ok && p.sample_middle[k] > 0.0;
      sample_ratio[k] = ok ? p.sample_fine[k] / p.sample_middle[k] : 0.0;
    }
    if (ok)
      sigma[n] = SigmaMatchingRatio(p.photo_fine / p.photo_middle, sample_ratio, kCandidateStep);
  }
  return sigma;
}

std::vector<double> PhotoBlurEstimator::SolvePerCamera(
    const std::vector<std::uint32_t>& camera_of_photo) const {
  TEXLUME_CHECK(camera_of_photo.size() == photos_.size(),
                "PhotoBlurEstimator: one camera per photo");
  const std::vector<double> per_photo = SolvePerPhoto();
  std::map<std::uint32_t, std::vector<double>> by_camera;
  for (std::size_t n = 0; n < photos_.size(); ++n)
    if (photos_[n].faces > 0) by_camera[camera_of_photo[n]].push_back(per_photo[n]);
  std::map<std::uint32_t, double> median;
  for (auto& [camera, sigmas] : by_camera) {
    const auto middle = sigmas.begin() + static_cast<std::ptrdiff_t>(sigmas.size() / 2);
    std::nth_element(sigmas.begin(), middle, sigmas.end());
    median[camera] = *middle;
  }
  std::vector<double> sigma(photos_.size(), 0.0);
  for (std::size_t n = 0; n < photos_.size(); ++n) {
    const auto it = median.find(camera_of_photo[n]);
    if (it != median.end()) sigma[n] = it->second;
  }
  return sigma;
}

}  // namespace texlume::synth
