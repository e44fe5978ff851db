#include "quilt/patch_energy.h"

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace texlume::quilt {

PatchEnergy NearestPatchEnergy(const std::vector<cv::Mat>& planes, const cv::Mat& inside,
                               RotatedSample& sample, const PatchEnergyOptions& options) {
  if (planes.empty() || inside.type() != CV_8UC1 || inside.size() != planes[0].size())
    throw std::invalid_argument("NearestPatchEnergy: planes and a CV_8UC1 mask of their size");
  const int w = options.window;
  // Window corners whose whole window is inside: the eroded mask's pixels.
  cv::Mat eroded;
  cv::erode(inside > 0, eroded, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(w, w)),
            cv::Point(0, 0));
  std::vector<cv::Point> corners;
  for (int y = 0; y + w <= eroded.rows; ++y)
    for (int x = 0; x + w <= eroded.cols; ++x)
      if (eroded.at<std::uint8_t>(y, x)) corners.emplace_back(x, y);
  std::mt19937_64 rng(options.seed);
  std::shuffle(corners.begin(), corners.end(), rng);
  corners.resize(std::min<std::size_t>(corners.size(), static_cast<std::size_t>(options.windows)));
  const cv::Mat mask(w, w, CV_32FC1, cv::Scalar(1));
  const int step = std::max(1, RotatedSample::kRotations / std::max(1, options.rotations));
  // Rotations outside, windows inside: each rotated copy is made once.
  std::vector<std::vector<cv::Mat>> windows;
  for (const cv::Point& corner : corners) {
    windows.emplace_back();
    for (const cv::Mat& plane : planes)
      windows.back().push_back(plane(cv::Rect(corner, cv::Size(w, w))));
  }
  std::vector<double> best(windows.size(), std::numeric_limits<double>::max());
  for (int r = 0; r < RotatedSample::kRotations; r += step) {
    const RotatedCopy& copy = sample.Copy(r);
    for (std::size_t i = 0; i < windows.size(); ++i)
      best[i] = std::min(best[i], MatchEntirePatch(copy, windows[i], mask).cost);
  }
  PatchEnergy energy;
  double sum = 0;
  for (const double b : best) sum += b;
  energy.windows = static_cast<int>(best.size());
  energy.per_texel = energy.windows ? sum / energy.windows : 0.0;
  return energy;
}

}  // namespace texlume::quilt
