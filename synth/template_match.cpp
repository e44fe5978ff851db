#include "synth/template_match.h"

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace texlume::synth {

cv::Mat PlaneEnergy(const std::vector<cv::Mat>& planes) {
  cv::Mat energy = cv::Mat::zeros(planes.at(0).size(), CV_32FC1);
  for (const cv::Mat& p : planes) cv::accumulateSquare(p, energy);
  return energy;
}

cv::Mat MaskedSsd(const std::vector<cv::Mat>& image_planes, const cv::Mat& image_energy,
                  const std::vector<cv::Mat>& template_planes, const cv::Mat& mask) {
  if (image_planes.size() != template_planes.size() || image_planes.empty()) {
    throw std::invalid_argument("MaskedSsd: one template plane per image plane");
  }
  cv::Mat result, term;
  cv::matchTemplate(image_energy, mask, result, cv::TM_CCORR);  // corr(sum I^2, M)
  double constant = 0.0;
  cv::Mat masked;
  for (std::size_t c = 0; c < image_planes.size(); ++c) {
    cv::multiply(template_planes[c], mask, masked);
    constant += masked.dot(template_planes[c]);
    cv::matchTemplate(image_planes[c], masked, term, cv::TM_CCORR);
    cv::scaleAdd(term, -2.0, result, result);
  }
  result += constant;
  cv::max(result, 0.0, result);
  return result;
}

int FastDftSize(int n) {
  int best = std::numeric_limits<int>::max();
  for (const int odd : {1, 3, 5}) {
    int m = odd;
    while (m < n) m *= 2;
    best = std::min(best, m);
  }
  return best;
}

namespace {

// The DFT of a plane zero-padded to `padded` (only its rows are transformed
// forward: the rest is zero).
cv::Mat Spectrum(const cv::Mat& plane, cv::Size padded) {
  cv::Mat zeros = cv::Mat::zeros(padded, CV_32FC1), spectrum;
  plane.copyTo(zeros(cv::Rect(0, 0, plane.cols, plane.rows)));
  cv::dft(zeros, spectrum, 0, plane.rows);
  return spectrum;
}

}  // namespace

ImageSpectra::ImageSpectra(const std::vector<cv::Mat>& planes, const cv::Mat& energy)
    : image_(energy.size()), padded_(FastDftSize(image_.width), FastDftSize(image_.height)) {
  for (const cv::Mat& plane : planes) plane_spectra_.push_back(Spectrum(plane, padded_));
  energy_spectrum_ = Spectrum(energy, padded_);
}

cv::Mat ImageSpectra::MaskedSsd(const std::vector<cv::Mat>& template_planes,
                                const cv::Mat& mask) const {
  // As synth::MaskedSsd: corr(E, M) - 2 sum_c corr(I_c, M T_c) + sum_c sum M T_c^2,
  // the correlations summed in the frequency domain; only the placements' rows
  // are transformed back.
  if (template_planes.size() != plane_spectra_.size() || plane_spectra_.empty())
    throw std::invalid_argument("ImageSpectra::MaskedSsd: one template plane per image plane");
  cv::Mat padded = cv::Mat::zeros(padded_, CV_32FC1), spectrum, term, sum, masked;
  const cv::Rect work(0, 0, mask.cols, mask.rows);
  mask.copyTo(padded(work));
  cv::dft(padded, spectrum, 0, mask.rows);
  cv::mulSpectrums(energy_spectrum_, spectrum, sum, 0, true);
  double constant = 0;
  for (std::size_t c = 0; c < template_planes.size(); ++c) {
    cv::multiply(template_planes[c], mask, masked);
    constant += masked.dot(template_planes[c]);
    masked.copyTo(padded(work));
    cv::dft(padded, spectrum, 0, mask.rows);
    cv::mulSpectrums(plane_spectra_[c], spectrum, term, 0, true);
    cv::scaleAdd(term, -2.0, sum, sum);
  }
  const cv::Size placements(image_.width - mask.cols + 1, image_.height - mask.rows + 1);
  cv::Mat full;
  cv::dft(sum, full, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT, placements.height);
  cv::Mat ssd = full(cv::Rect(cv::Point(0, 0), placements)) + constant;
  cv::max(ssd, 0.0, ssd);
  return ssd;
}

cv::Mat MaskedSsdBruteForce(const std::vector<cv::Mat>& image_planes,
                            const std::vector<cv::Mat>& template_planes, const cv::Mat& mask) {
  const int w = image_planes[0].cols - mask.cols + 1, h = image_planes[0].rows - mask.rows + 1;
  cv::Mat out(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double sum = 0.0;
      for (std::size_t c = 0; c < image_planes.size(); ++c) {
        for (int j = 0; j < mask.rows; ++j) {
          for (int i = 0; i < mask.cols; ++i) {
            const double d =
                template_planes[c].at<float>(j, i) - image_planes[c].at<float>(y + j, x + i);
            sum += mask.at<float>(j, i) * d * d;
          }
        }
      }
      out.at<float>(y, x) = static_cast<float>(sum);
    }
  }
  return out;
}

namespace {

// Classic quilting's rule over `count` errors error(i): the index, uniform from
// `rng`, of one of those within (1 + tolerance) of the smallest.
template <typename ErrorAt>
std::size_t PickIndexWithinTolerance(std::size_t count, ErrorAt error, double tolerance,
                                     std::mt19937_64& rng) {
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < count; ++i) least = std::min(least, error(i));
  std::vector<std::size_t> near;
  for (std::size_t i = 0; i < count; ++i)
    if (error(i) <= least * (1.0 + tolerance) + 1e-12) near.push_back(i);
  return near[std::uniform_int_distribution<std::size_t>(0, near.size() - 1)(rng)];
}

}  // namespace

cv::Point PickWithinTolerance(const cv::Mat& errors, double tolerance, std::mt19937_64& rng) {
  const auto cols = static_cast<std::size_t>(errors.cols);
  const auto error = [&](std::size_t i) {
    return static_cast<double>(
        errors.at<float>(static_cast<int>(i / cols), static_cast<int>(i % cols)));
  };
  const std::size_t i = PickIndexWithinTolerance(errors.total(), error, tolerance, rng);
  return {static_cast<int>(i % cols), static_cast<int>(i / cols)};
}

std::size_t PickWithinTolerance(const std::vector<double>& errors, double tolerance,
                                std::mt19937_64& rng) {
  return PickIndexWithinTolerance(
      errors.size(), [&](std::size_t i) { return errors[i]; }, tolerance, rng);
}

}  // namespace texlume::synth
