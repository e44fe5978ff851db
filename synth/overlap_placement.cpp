#include "synth/overlap_placement.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <tuple>
#include <unordered_set>

#include "core/check.h"

namespace texlume::synth {
namespace {

// Planes averaged over blocks of `block` x `block` texels, mirrored past their right
// and bottom edges to one block beyond the last partial one: a patch of any size
// then has a coarse placement within half a block of its last placement at full
// density (the coarse grid's last ones read the mirrored texels).
std::vector<cv::Mat> BlockAverages(const std::vector<cv::Mat>& planes, int block) {
  const cv::Size blocks((planes[0].cols + block - 1) / block + 1,
                        (planes[0].rows + block - 1) / block + 1);
  std::vector<cv::Mat> out(planes.size());
  for (std::size_t c = 0; c < planes.size(); ++c) {
    cv::Mat mirrored;
    cv::copyMakeBorder(planes[c], mirrored, 0, blocks.height * block - planes[c].rows, 0,
                       blocks.width * block - planes[c].cols, cv::BORDER_REFLECT_101);
    cv::resize(mirrored, out[c], blocks, 0, 0, cv::INTER_AREA);
  }
  return out;
}

// A plane of the patch's size padded with zeros to whole blocks.
cv::Mat PaddedToBlocks(const cv::Mat& plane, int block) {
  cv::Mat padded;
  cv::copyMakeBorder(plane, padded, 0, (block - plane.rows % block) % block, 0,
                     (block - plane.cols % block) % block, cv::BORDER_CONSTANT, cv::Scalar(0));
  return padded;
}

}  // namespace

double OverlapTexels::SumOfSquares(const std::vector<cv::Mat>& features, cv::Point at) const {
  const std::size_t n = features.size();
  // Each plane's texel at the patch's top left and its row step (floats).
  std::vector<const float*> at_corner(n);
  std::vector<std::size_t> row(n);
  for (std::size_t c = 0; c < n; ++c)
    at_corner[c] = features[c].ptr<float>(at.y) + at.x, row[c] = features[c].step1();
  double e = 0.0;
  for (std::size_t m = 0; m < texels.size(); ++m) {
    const auto texel = static_cast<std::size_t>(texels[m]);
    const std::size_t j = texel / static_cast<std::size_t>(patch.width),
                      i = texel % static_cast<std::size_t>(patch.width);
    for (std::size_t c = 0; c < n; ++c) {
      const double d = at_corner[c][j * row[c] + i] - targets[m * n + c];
      e += d * d;
    }
  }
  return e;
}

OverlapPlacement::OverlapPlacement(const std::vector<cv::Mat>& features) : features_(features) {
  TEXLUME_CHECK(!features.empty(), "the overlap placement needs the sample's feature planes");
}

int OverlapPlacement::Halvings(cv::Size patch) const {
  const cv::Size sample = features_[0].size();
  int halvings = 0;
  for (int h = 1; h <= kMaxHalvings; ++h) {
    const int block = 1 << h;
    // The patch keeps kMinCells blocks a side and fits the reduced sample, and the
    // refined placements are well below every placement (as the photos' search).
    const bool fits = std::min(patch.width, patch.height) / block >= kMinCells &&
                      (patch.width + block - 1) / block <= sample.width / block &&
                      (patch.height + block - 1) / block <= sample.height / block;
    const double everywhere =
        (sample.width - patch.width + 1.0) * (sample.height - patch.height + 1.0);
    const double refined = kCandidates * (block + 1.0) * (block + 1.0);
    if (!fits || everywhere < 4.0 * refined) break;
    halvings = h;
  }
  return halvings;
}

std::vector<cv::Mat> OverlapPlacement::TargetPlanes(const OverlapTexels& overlap,
                                                    cv::Mat& mask) const {
  const std::size_t n = features_.size();
  std::vector<cv::Mat> planes(n);
  for (cv::Mat& m : planes) m = cv::Mat::zeros(overlap.patch, CV_32FC1);
  mask = cv::Mat::zeros(overlap.patch, CV_32FC1);
  for (std::size_t m = 0; m < overlap.texels.size(); ++m) {
    const int i = overlap.texels[m] % overlap.patch.width,
              j = overlap.texels[m] / overlap.patch.width;
    mask.at<float>(j, i) = 1.0f;
    for (std::size_t c = 0; c < n; ++c) planes[c].at<float>(j, i) = overlap.targets[m * n + c];
  }
  return planes;
}

const ImageSpectra& OverlapPlacement::SpectraAt(int halvings) {
  if (const auto it = spectra_.find(halvings); it != spectra_.end()) return it->second;
  const std::vector<cv::Mat> planes =
      halvings == 0 ? features_ : BlockAverages(features_, 1 << halvings);
  return spectra_.emplace(halvings, ImageSpectra(planes, PlaneEnergy(planes))).first->second;
}

std::vector<cv::Point> OverlapPlacement::Refined(const cv::Mat& coarse_errors, int halvings,
                                                 cv::Size patch) const {
  // The best coarse placements (ties in row order), each standing for the block of
  // full-density placements it starts.
  std::vector<std::tuple<float, int, int>> coarse;
  for (int y = 0; y < coarse_errors.rows; ++y)
    for (int x = 0; x < coarse_errors.cols; ++x)
      coarse.emplace_back(coarse_errors.at<float>(y, x), y, x);
  const std::size_t kept = std::min<std::size_t>(kCandidates, coarse.size());
  std::partial_sort(coarse.begin(), coarse.begin() + static_cast<std::ptrdiff_t>(kept),
                    coarse.end());
  const int block = 1 << halvings, half = block / 2;
  const int last_x = features_[0].cols - patch.width, last_y = features_[0].rows - patch.height;
  std::unordered_set<long long> seen;
  std::vector<cv::Point> near;
  for (std::size_t k = 0; k < kept; ++k) {
    // Coarse placements past the last one at full density (on the mirrored blocks)
    // stand for the last ones.
    const int cx = std::min(std::get<2>(coarse[k]) * block, last_x + half);
    const int cy = std::min(std::get<1>(coarse[k]) * block, last_y + half);
    for (int y = std::max(0, cy - half); y <= std::min(last_y, cy + half); ++y)
      for (int x = std::max(0, cx - half); x <= std::min(last_x, cx + half); ++x)
        if (seen.insert(static_cast<long long>(y) * (last_x + 1) + x).second)
          near.emplace_back(x, y);
  }
  return near;
}

OverlapPlacement::Placement OverlapPlacement::Pick(const OverlapTexels& overlap, double tolerance,
                                                   std::mt19937_64& rng) {
  TEXLUME_CHECK(!overlap.texels.empty(), "a placement by the neighbours needs an overlap");
  cv::Mat mask;
  const std::vector<cv::Mat> targets = TargetPlanes(overlap, mask);
  const int halvings = Halvings(overlap.patch);
  if (halvings == 0) {  // every placement at full density
    const cv::Mat errors = SpectraAt(0).MaskedSsd(targets, mask);
    const cv::Point p = PickWithinTolerance(errors, tolerance, rng);
    return {p, errors.at<float>(p.y, p.x)};
  }
  // The overlap averaged over blocks, weighted by how much of each block it covers.
  const int block = 1 << halvings;
  const cv::Mat padded_mask = PaddedToBlocks(mask, block);
  const cv::Size blocks(padded_mask.cols / block, padded_mask.rows / block);
  cv::Mat coarse_mask;
  cv::resize(padded_mask, coarse_mask, blocks, 0, 0, cv::INTER_AREA);
  std::vector<cv::Mat> coarse_targets(targets.size());
  for (std::size_t c = 0; c < targets.size(); ++c) {
    cv::Mat weighted;
    cv::resize(PaddedToBlocks(targets[c].mul(mask), block), weighted, blocks, 0, 0, cv::INTER_AREA);
    cv::divide(weighted, coarse_mask, coarse_targets[c]);
    coarse_targets[c].setTo(0.0f, coarse_mask <= 0.0f);  // 0 / 0: nothing there
  }
  const cv::Mat coarse_errors = SpectraAt(halvings).MaskedSsd(coarse_targets, coarse_mask);
  const std::vector<cv::Point> near = Refined(coarse_errors, halvings, overlap.patch);
  std::vector<double> errors(near.size());
  for (std::size_t n = 0; n < near.size(); ++n)
    errors[n] = overlap.SumOfSquares(features_, near[n]);
  const std::size_t chosen = PickWithinTolerance(errors, tolerance, rng);
  return {near[chosen], errors[chosen]};
}

}  // namespace texlume::synth
