#include "quilt/patch_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "synth/template_match.h"

namespace texlume::quilt {
namespace {

Placement BestOf(const cv::Mat& ssd, int rotation, double overlap) {
  Placement best;
  best.rotation = rotation;
  best.cost = std::numeric_limits<double>::max();
  for (int y = 0; y < ssd.rows; ++y) {
    const float* row = ssd.ptr<float>(y);
    for (int x = 0; x < ssd.cols; ++x)
      if (row[x] < best.cost) best.cost = row[x], best.x = x, best.y = y;
  }
  best.cost /= std::max(overlap, 1.0);
  return best;
}

void CheckWorkImage(const RotatedCopy& copy, const std::vector<cv::Mat>& work_planes,
                    const cv::Mat& work_mask) {
  if (work_planes.size() != copy.planes.size() || work_mask.type() != CV_32FC1)
    throw std::invalid_argument("MatchEntirePatch: one work plane per feature, a CV_32FC1 mask");
  if (work_mask.cols > copy.side() || work_mask.rows > copy.side())
    throw std::invalid_argument("MatchEntirePatch: the work image (" +
                                std::to_string(work_mask.cols) + " x " +
                                std::to_string(work_mask.rows) + ") is larger than the copies (" +
                                std::to_string(copy.side()) + ")");
}

}  // namespace

RotatedSample::RotatedSample(const synth::MaterialSample& sample, std::size_t cached_copies)
    : sample_(sample),
      budget_(std::max<std::size_t>(cached_copies, 1)),
      side_(static_cast<int>(
          std::floor(std::min(sample.Width(), sample.Height()) / std::numbers::sqrt2))) {
  if (side_ < 8)
    throw InputError("the " + sample.Name() + " sample",
                     "is " + std::to_string(sample.Width()) + " x " +
                         std::to_string(sample.Height()) +
                         " texels; graph-cut quilting needs at least 12 x 12");
}

int RotatedSample::RotationNearest(double angle_rad) {
  const double turns = angle_rad / (2 * std::numbers::pi);
  const long r = std::lround((turns - std::floor(turns)) * kRotations);
  return static_cast<int>(r % kRotations);
}

double RotatedSample::AngleOf(int rotation) { return 2 * std::numbers::pi * rotation / kRotations; }

Eigen::Vector2d RotatedSample::SamplePosition(int rotation, const Eigen::Vector2d& copy_px) const {
  // The copy shows the sample turned by +angle (y up): a copy offset v (rows
  // down) comes from the sample offset turned by -angle, here in rows-down terms.
  const double a = AngleOf(rotation), c = std::cos(a), s = std::sin(a);
  const Eigen::Vector2d v = copy_px - Eigen::Vector2d(side_ / 2.0, side_ / 2.0);
  return Eigen::Vector2d(sample_.Width() / 2.0, sample_.Height() / 2.0) +
         Eigen::Vector2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

RotatedCopy RotatedSample::Make(int rotation) const {
  RotatedCopy copy;
  copy.rotation = rotation;
  copy.angle_rad = AngleOf(rotation);
  const int n = sample_.NumFeatures();
  for (int c = 0; c < n; ++c) copy.planes.emplace_back(side_, side_, CV_32FC1);
  // The copy's frame is the sample's turned by -angle: its features are the
  // sample's carried into it (synth::Unfolding: p_sample = R(-angle) p_copy).
  synth::Unfolding turn;
  turn.rotation = Eigen::Rotation2Dd(-copy.angle_rad).toRotationMatrix();
  turn.coefficients_to_this = ptm::OrthonormalFrameRotation(-copy.angle_rad);
  std::vector<float> f(static_cast<std::size_t>(n));
  for (int y = 0; y < side_; ++y)
    for (int x = 0; x < side_; ++x) {
      sample_.FeaturesAt(SamplePosition(rotation, Eigen::Vector2d(x + 0.5, y + 0.5)), f.data());
      sample_.TurnFeatures(turn, f.data());
      for (int c = 0; c < n; ++c)
        copy.planes[static_cast<std::size_t>(c)].at<float>(y, x) = f[static_cast<std::size_t>(c)];
    }
  copy.energy = synth::PlaneEnergy(copy.planes);
  copy.spectra = synth::ImageSpectra(copy.planes, copy.energy);
  return copy;
}

std::vector<cv::Mat> RotatedSample::TurnPlanes(int rotation,
                                               const std::vector<cv::Mat>& sample_planes) const {
  // SamplePosition as an affine map from copy pixel indices to sample pixel
  // indices (centres at +0.5 on both sides).
  const double a = AngleOf(rotation), c = std::cos(a), s = std::sin(a);
  const double h = side_ / 2.0 - 0.5;
  cv::Mat copy_to_sample =
      (cv::Mat_<double>(2, 3) << c, -s, sample_.Width() / 2.0 - 0.5 - c * h + s * h, s, c,
       sample_.Height() / 2.0 - 0.5 - s * h - c * h);
  std::vector<cv::Mat> turned(sample_planes.size());
  for (std::size_t p = 0; p < sample_planes.size(); ++p)
    cv::warpAffine(sample_planes[p], turned[p], copy_to_sample, cv::Size(side_, side_),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  return turned;
}

const RotatedCopy& RotatedSample::Copy(int rotation) {
  if (rotation < 0 || rotation >= kRotations)
    throw std::out_of_range("RotatedSample::Copy: rotation " + std::to_string(rotation));
  for (auto it = cache_.begin(); it != cache_.end(); ++it)
    if (it->rotation == rotation) {
      cache_.splice(cache_.begin(), cache_, it);
      return cache_.front();
    }
  cache_.push_front(Make(rotation));
  if (cache_.size() > budget_) cache_.pop_back();
  return cache_.front();
}

cv::Mat EntirePatchCosts(const RotatedCopy& copy, const std::vector<cv::Mat>& work_planes,
                         const cv::Mat& work_mask) {
  CheckWorkImage(copy, work_planes, work_mask);
  return copy.spectra.MaskedSsd(work_planes, work_mask) / std::max(cv::sum(work_mask)[0], 1.0);
}

Placement MatchEntirePatch(const RotatedCopy& copy, const std::vector<cv::Mat>& work_planes,
                           const cv::Mat& work_mask) {
  CheckWorkImage(copy, work_planes, work_mask);
  return BestOf(copy.spectra.MaskedSsd(work_planes, work_mask), copy.rotation,
                cv::sum(work_mask)[0]);
}

Placement MatchEntirePatchBruteForce(const RotatedCopy& copy,
                                     const std::vector<cv::Mat>& work_planes,
                                     const cv::Mat& work_mask) {
  CheckWorkImage(copy, work_planes, work_mask);
  return BestOf(synth::MaskedSsdBruteForce(copy.planes, work_planes, work_mask), copy.rotation,
                cv::sum(work_mask)[0]);
}

}  // namespace texlume::quilt
