#include "synth/template_match.h"

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

cv::Point PickWithinTolerance(const cv::Mat& errors, double tolerance, std::mt19937_64& rng) {
  double min_error;
  cv::minMaxLoc(errors, &min_error);
  std::vector<cv::Point> near;
  for (int y = 0; y < errors.rows; ++y)
    for (int x = 0; x < errors.cols; ++x)
      if (errors.at<float>(y, x) <= min_error * (1.0 + tolerance) + 1e-12) near.emplace_back(x, y);
  return near[std::uniform_int_distribution<std::size_t>(0, near.size() - 1)(rng)];
}

}  // namespace texlume::synth
