#include "synth/planar_synthesis.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "synth/template_match.h"

namespace texlume::synth {
namespace {

// Number of planes that carry polynomial coefficients (compared by the overlap
// constraint); LRGB's colour planes follow them and are only carried along.
int CoefficientPlanes(ptm::PtmFormat format) { return format == ptm::PtmFormat::kLrgb ? 6 : 18; }

std::vector<cv::Mat> Roi(const std::vector<cv::Mat>& planes, const cv::Rect& r, int count) {
  std::vector<cv::Mat> out;
  for (int c = 0; c < count; ++c) out.push_back(planes[static_cast<std::size_t>(c)](r));
  return out;
}

// Block start positions along an axis of `length` texels: every `step`, the
// last one flush with the end.
std::vector<int> Positions(int length, int block, int step) {
  std::vector<int> p;
  for (int x = 0; x + block < length; x += step) p.push_back(x);
  p.push_back(length - block);
  return p;
}

// Minimum-cost vertical path through an error strip (rows x cols): returns, per
// row, the column where the new block starts (texels left of it keep the old).
std::vector<int> VerticalSeam(const cv::Mat& error) {
  const int rows = error.rows, cols = error.cols;
  cv::Mat cost = error.clone();
  for (int y = 1; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      float best = cost.at<float>(y - 1, x);
      if (x > 0) best = std::min(best, cost.at<float>(y - 1, x - 1));
      if (x + 1 < cols) best = std::min(best, cost.at<float>(y - 1, x + 1));
      cost.at<float>(y, x) += best;
    }
  }
  std::vector<int> path(static_cast<std::size_t>(rows));
  int x = 0;
  for (int i = 1; i < cols; ++i) {
    if (cost.at<float>(rows - 1, i) < cost.at<float>(rows - 1, x)) x = i;
  }
  for (int y = rows - 1; y >= 0; --y) {
    path[static_cast<std::size_t>(y)] = x;
    if (y == 0) break;
    int best = x;
    for (int dx = -1; dx <= 1; ++dx) {
      const int c = x + dx;
      if (c >= 0 && c < cols && cost.at<float>(y - 1, c) < cost.at<float>(y - 1, best)) best = c;
    }
    x = best;
  }
  return path;
}

}  // namespace

void PlanarSynthesisOptions::Check() const {
  if (width < 0 || height < 0) throw OptionError("width and height must be >= 0");
  if (width > kMaxOutputSide || height > kMaxOutputSide) {
    throw OptionError("width and height must be at most " + std::to_string(kMaxOutputSide) +
                      " texels");
  }
  if (block_size < 4) throw OptionError("block_size must be >= 4");
  if (overlap < 1 || overlap >= block_size) throw OptionError("overlap must be in [1, block_size)");
  if (top_k < 1) throw OptionError("top_k must be >= 1");
  if (scale < 1) throw OptionError("scale must be >= 1");
  if (!(tolerance >= 0.0)) throw OptionError("tolerance must be >= 0");
  if (correction_iterations < 0 || correction_iterations > 20)
    throw OptionError("correction_iterations must be in [0, 20]");
}

std::vector<cv::Mat> ToOrthonormalPlanes(const ptm::Ptm& ptm) {
  const auto& to = ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
  std::vector<cv::Mat> planes;
  const int polys = ptm.NumPolynomials();
  for (int c = 0; c < polys * 6 + (ptm.format == ptm::PtmFormat::kLrgb ? 3 : 0); ++c) {
    planes.emplace_back(ptm.height, ptm.width, CV_32FC1);
  }
  for (int y = 0; y < ptm.height; ++y) {
    for (int x = 0; x < ptm.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * ptm.width + x;
      for (int p = 0; p < polys; ++p) {
        Eigen::Matrix<double, 6, 1> a;
        for (int i = 0; i < 6; ++i) a[i] = ptm.Coefficients(t, p)[i];
        const Eigen::Matrix<double, 6, 1> o = to * a;
        for (int i = 0; i < 6; ++i)
          planes[static_cast<std::size_t>(p * 6 + i)].at<float>(y, x) = static_cast<float>(o[i]);
      }
      if (ptm.format == ptm::PtmFormat::kLrgb) {
        for (int c = 0; c < 3; ++c)
          planes[static_cast<std::size_t>(6 + c)].at<float>(y, x) =
              ptm.colour[t * 3 + static_cast<std::size_t>(c)];
      }
    }
  }
  return planes;
}

ptm::Ptm FromOrthonormalPlanes(const std::vector<cv::Mat>& planes, ptm::PtmFormat format) {
  const auto& from = ptm::OrthonormalBasis::Hemisphere().FromOrthonormal();
  ptm::Ptm out;
  out.Resize(format, planes[0].cols, planes[0].rows);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * out.width + x;
      for (int p = 0; p < out.NumPolynomials(); ++p) {
        Eigen::Matrix<double, 6, 1> o;
        for (int i = 0; i < 6; ++i)
          o[i] = planes[static_cast<std::size_t>(p * 6 + i)].at<float>(y, x);
        const Eigen::Matrix<double, 6, 1> a = from * o;
        for (int i = 0; i < 6; ++i) out.Coefficients(t, p)[i] = static_cast<float>(a[i]);
      }
      if (format == ptm::PtmFormat::kLrgb) {
        for (int c = 0; c < 3; ++c)
          out.colour[t * 3 + static_cast<std::size_t>(c)] =
              planes[static_cast<std::size_t>(6 + c)].at<float>(y, x);
      }
    }
  }
  return out;
}

namespace {

// Patch-based planar PTM quilting, Algorithm 1 of Rajiv & Namboodiri
// (003_4d5d2fd6ae323cf0.txt): PTM_out is traversed block by block in raster order from the
// lower-left corner; at each position a set s of candidate blocks of PTM_in is chosen by the
// image constraint (eq. 3), the block B_k that best fits the overlap constraint is picked,
// pasted, and blended (or cut along the min-error boundary) in the overlap.
class PlanarSynthesis {
 public:
  PlanarSynthesis(const ptm::Ptm& sample, const std::vector<PlanarPhoto>& photos,
                  const PlanarSynthesisOptions& options)
      : sample_(sample),
        photos_(photos),
        options_(options),
        constrained_(options.use_photos && !photos.empty()),
        block_(options.block_size),
        step_(options.block_size - options.overlap),
        rng_(options.seed) {}

  // Runs Algorithm 1, then the photo-consistency pass; all but the timing of the result.
  PlanarSynthesisResult Run();

 private:
  // Block B_k's position (x, y) in PTM_out and what PTM_out holds there.
  struct Site {
    std::size_t ix = 0, iy = 0;  // indices into xs_, ys_
    int x = 0, y = 0;
    cv::Rect out_rect;
    cv::Mat mask;  // texels of the block already filled
    bool has_overlap = false;
    std::vector<cv::Mat> out_block;  // coefficient planes of PTM_out under the block
    double overlap_texels = 1.0;     // filled texels under the block, at least 1
  };
  using Candidates = std::vector<std::pair<double, cv::Point>>;  // (image score, position)

  // Checks the photos and sets the output extent and the photo scale.
  void ResolveExtent();
  // Checks that a block fits the sample and the output, at whole photo pixels.
  void CheckBlock() const;
  // PTM_in in the orthonormal space, with its coefficient planes' energy.
  void PrepareSample();
  // PTM_in relit at each photo's light, at the photo's resolution, times its gain.
  void RelightSample();
  // Step 1: traverses PTM_out in raster order from the lower-left corner.
  void Traverse();
  // Steps 2-4 at one block position.
  void SynthesizeBlock(std::size_t ix, std::size_t iy);
  // Step 2: the top_k candidate blocks by the image score S(B) (eq. 3).
  Candidates ImageCandidates(const Site& site) const;
  // Step 3: the block B_k to paste (by overlap error, at random, or within tolerance).
  BlockPlacement ChooseBlock(const Site& site);
  // Step 3, constrained: the candidate with the least overlap error.
  void PickByOverlap(const Site& site, const Candidates& candidates,
                     BlockPlacement& placement) const;
  // Step 4: the weight of the new block per texel (blend ramps or min-error cut).
  cv::Mat StitchAlpha(const Site& site, const cv::Rect& sample_rect);
  // Squared coefficient difference of the new block and PTM_out under it.
  cv::Mat OverlapError(const Site& site, const cv::Rect& sample_rect) const;
  // Linear blend ramps across the overlap; seam texels on their 50 % lines.
  void BlendRamps(const cv::Mat& error, int left, int bottom, cv::Mat& alpha);
  // The minimum-error boundary cut through the left and bottom overlaps.
  void MinErrorCut(const cv::Mat& error, int left, int bottom, cv::Mat& alpha);
  // Step 4: pastes the block, weighted by alpha, and marks its texels filled.
  void Paste(const Site& site, const cv::Rect& sample_rect, const cv::Mat& alpha);
  // PTM_out from the planes, the photo-consistency pass and the seam cost.
  void Output();

  const ptm::Ptm& sample_;
  const std::vector<PlanarPhoto>& photos_;
  PlanarSynthesisOptions options_;
  PlanarSynthesisResult result_;
  const bool constrained_;
  int scale_ = 1;           // texels per photo pixel
  const int block_, step_;  // block size, and its stride (block size - overlap)

  ptm::PtmFormat format_ = ptm::PtmFormat::kRgb;
  int coefficient_planes_ = 0;
  std::vector<cv::Mat> sample_planes_, sample_coefficients_;
  cv::Mat sample_energy_;

  std::vector<std::vector<cv::Mat>> relit_small_;  // [photo][channel]
  std::vector<cv::Mat> relit_energy_;
  std::vector<std::vector<cv::Mat>> photo_planes_;

  std::vector<cv::Mat> out_;  // orthonormal coefficients, colour
  cv::Mat filled_;
  std::mt19937_64 rng_;
  double seam_sum_ = 0.0;
  std::size_t seam_texels_ = 0;
  std::vector<int> xs_, ys_;
};

PlanarSynthesisResult PlanarSynthesis::Run() {
  if (options_.use_photos && photos_.empty()) {
    throw InputError("photos", "constrained synthesis needs at least one photo");
  }
  ResolveExtent();
  CheckBlock();
  PrepareSample();
  RelightSample();
  Traverse();
  Output();
  return std::move(result_);
}

void PlanarSynthesis::ResolveExtent() {
  // Output extent and photo scale (texels per photo pixel, an integer).
  int scale = 1;
  if (!photos_.empty()) {
    const int pw = photos_[0].image.width, ph = photos_[0].image.height;
    for (const PlanarPhoto& p : photos_) {
      if (p.image.width != pw || p.image.height != ph) {
        throw InputError(p.name, "is " + std::to_string(p.image.width) + "x" +
                                     std::to_string(p.image.height) + ", but " + photos_[0].name +
                                     " is " + std::to_string(pw) + "x" + std::to_string(ph));
      }
      if (!(p.light.z() > 0.0) || std::abs(p.light.norm() - 1.0) > 1e-6) {
        throw InputError(p.name, "its light must be a unit vector above the horizon");
      }
    }
    if (options_.width == 0) options_.width = pw * options_.scale;
    if (options_.height == 0) options_.height = options_.width * ph / pw;
    if (options_.width % pw != 0 || options_.width / pw * ph != options_.height) {
      throw InputError(photos_[0].name, "photos of " + std::to_string(pw) + "x" +
                                            std::to_string(ph) + " do not cover a " +
                                            std::to_string(options_.width) + "x" +
                                            std::to_string(options_.height) +
                                            " output at a whole number of texels per pixel");
    }
    scale = options_.width / pw;
  }
  if (options_.width == 0 || options_.height == 0) {
    throw OptionError("give the output size (width, height) for unconstrained synthesis");
  }
  scale_ = scale;
  result_.scale = scale;
}

void PlanarSynthesis::CheckBlock() const {
  const int block = block_, step = step_, scale = scale_;
  if (block > sample_.width || block > sample_.height) {
    throw OptionError("block_size " + std::to_string(block) + " does not fit the " +
                      std::to_string(sample_.width) + "x" + std::to_string(sample_.height) +
                      " sample");
  }
  if (block > options_.width || block > options_.height) {
    throw OptionError("block_size is larger than the output");
  }
  if (block % scale != 0 || step % scale != 0) {
    throw OptionError("block_size and block_size - overlap must be multiples of the photo scale " +
                      std::to_string(scale));
  }
}

void PlanarSynthesis::PrepareSample() {
  format_ = sample_.format;
  coefficient_planes_ = CoefficientPlanes(format_);
  sample_planes_ = ToOrthonormalPlanes(sample_);
  sample_coefficients_.assign(sample_planes_.begin(), sample_planes_.begin() + coefficient_planes_);
  sample_energy_ = PlaneEnergy(sample_coefficients_);
}

void PlanarSynthesis::RelightSample() {
  // The sample relit at each photo's light, at the photo's resolution, times the
  // photo's gain (exposure x light intensity), as 3 planes per photo.
  const int scale = scale_;
  for (const PlanarPhoto& photo : photos_) {
    const std::vector<float> relit = ptm::Relight(sample_, photo.light);
    cv::Mat full(sample_.height, sample_.width, CV_32FC3, const_cast<float*>(relit.data()));
    cv::Mat small;
    cv::resize(full, small, cv::Size(sample_.width / scale, sample_.height / scale), 0, 0,
               cv::INTER_AREA);
    cv::Mat photo_mat(photo.image.height, photo.image.width, CV_32FC3,
                      const_cast<float*>(photo.image.pixels.data()));
    double gain = 1.0;
    if (options_.estimate_gain) {
      const double sample_mean = cv::mean(small)[0] + cv::mean(small)[1] + cv::mean(small)[2];
      const double photo_mean =
          cv::mean(photo_mat)[0] + cv::mean(photo_mat)[1] + cv::mean(photo_mat)[2];
      if (sample_mean > 1e-6) gain = photo_mean / sample_mean;
    }
    result_.photo_gains.push_back(gain);
    std::vector<cv::Mat> channels, photo_channels;
    cv::split(small * gain, channels);
    cv::split(photo_mat, photo_channels);
    relit_energy_.push_back(PlaneEnergy(channels));
    relit_small_.push_back(channels);
    for (cv::Mat& c : photo_channels) c = c.clone();
    photo_planes_.push_back(photo_channels);
  }
}

void PlanarSynthesis::Traverse() {
  // Output planes (orthonormal coefficients, colour) and which texels are filled.
  out_.resize(sample_planes_.size());
  for (cv::Mat& p : out_) p = cv::Mat::zeros(options_.height, options_.width, CV_32FC1);
  filled_ = cv::Mat::zeros(options_.height, options_.width, CV_32FC1);

  xs_ = Positions(options_.width, block_, step_);
  ys_ = Positions(options_.height, block_, step_);
  std::reverse(ys_.begin(), ys_.end());  // raster from the lower-left corner upwards
  for (std::size_t iy = 0; iy < ys_.size(); ++iy) {
    for (std::size_t ix = 0; ix < xs_.size(); ++ix) SynthesizeBlock(ix, iy);
  }
}

void PlanarSynthesis::SynthesizeBlock(std::size_t ix, std::size_t iy) {
  Site site;
  site.ix = ix;
  site.iy = iy;
  site.x = xs_[ix];
  site.y = ys_[iy];
  site.out_rect = cv::Rect(site.x, site.y, block_, block_);
  site.mask = filled_(site.out_rect).clone();
  site.has_overlap = cv::countNonZero(site.mask) > 0;
  site.out_block = Roi(out_, site.out_rect, coefficient_planes_);
  site.overlap_texels = std::max(1.0, cv::sum(site.mask)[0]);

  const BlockPlacement placement = ChooseBlock(site);
  result_.blocks.push_back(placement);

  // Paste and stitch in the orthonormal space.
  const cv::Rect sample_rect(placement.sample_x, placement.sample_y, block_, block_);
  const cv::Mat alpha = StitchAlpha(site, sample_rect);
  Paste(site, sample_rect, alpha);
}

PlanarSynthesis::Candidates PlanarSynthesis::ImageCandidates(const Site& site) const {
  const int x = site.x, y = site.y, block = block_, scale = scale_;
  // Candidates: positions in the sample (top-left corners).
  // S(B) = sum_n || g_n f(B, l_n) - b(I_n, x, y) || (eq. 3), at photo resolution.
  cv::Mat score;
  const cv::Rect photo_rect(x / scale, y / scale, block / scale, block / scale);
  const cv::Mat ones = cv::Mat::ones(photo_rect.size(), CV_32FC1);
  for (std::size_t n = 0; n < photos_.size(); ++n) {
    cv::Mat ssd =
        MaskedSsd(relit_small_[n], relit_energy_[n], Roi(photo_planes_[n], photo_rect, 3), ones);
    cv::sqrt(ssd, ssd);
    if (score.empty()) {
      score = ssd;
    } else {
      score += ssd;
    }
  }
  Candidates all;
  all.reserve(score.total());
  for (int py = 0; py < score.rows; ++py)
    for (int px = 0; px < score.cols; ++px)
      all.emplace_back(score.at<float>(py, px), cv::Point(px * scale, py * scale));
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(options_.top_k), all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  return Candidates(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k));
}

BlockPlacement PlanarSynthesis::ChooseBlock(const Site& site) {
  Candidates candidates;
  if (constrained_) candidates = ImageCandidates(site);

  BlockPlacement placement;
  placement.out_x = site.x;
  placement.out_y = site.y;
  if (constrained_) {
    PickByOverlap(site, candidates, placement);
  } else if (!site.has_overlap) {
    std::uniform_int_distribution<int> ux(0, sample_.width - block_),
        uy(0, sample_.height - block_);
    placement.sample_x = ux(rng_);
    placement.sample_y = uy(rng_);
  } else {
    // Unconstrained quilting: overlap error at every sample position (FFT).
    const cv::Mat errors =
        MaskedSsd(sample_coefficients_, sample_energy_, site.out_block, site.mask);
    const cv::Point p = PickWithinTolerance(errors, options_.tolerance, rng_);
    placement.sample_x = p.x;
    placement.sample_y = p.y;
    placement.overlap_error = errors.at<float>(p.y, p.x) / site.overlap_texels;
  }
  return placement;
}

void PlanarSynthesis::PickByOverlap(const Site& site, const Candidates& candidates,
                                    BlockPlacement& placement) const {
  const int block = block_, coefficient_planes = coefficient_planes_;
  // Overlap constraint among the image-ranked candidates.
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [s, p] : candidates) {
    double e = 0.0;
    if (site.has_overlap) {
      const std::vector<cv::Mat> cand =
          Roi(sample_planes_, cv::Rect(p.x, p.y, block, block), coefficient_planes);
      for (int c = 0; c < coefficient_planes; ++c) {
        cv::Mat d = cand[static_cast<std::size_t>(c)] - site.out_block[static_cast<std::size_t>(c)];
        e += d.mul(d).dot(site.mask);
      }
      e /= site.overlap_texels;
    }
    if (e < best || (e == best && s < placement.image_score)) {
      best = e;
      placement.sample_x = p.x;
      placement.sample_y = p.y;
      placement.image_score = s;
      placement.overlap_error = e;
    }
  }
}

cv::Mat PlanarSynthesis::StitchAlpha(const Site& site, const cv::Rect& sample_rect) {
  const int block = block_, x = site.x, y = site.y;
  const std::size_t ix = site.ix, iy = site.iy;
  cv::Mat alpha = cv::Mat::ones(block, block, CV_32FC1);  // weight of the new block
  if (site.has_overlap) {
    const int left = ix > 0 ? xs_[ix - 1] + block - x : 0;
    const int bottom = iy > 0 ? y + block - ys_[iy - 1] : 0;
    const cv::Mat error = OverlapError(site, sample_rect);
    if (options_.stitch == Stitch::kBlend) {
      BlendRamps(error, left, bottom, alpha);
    } else {
      MinErrorCut(error, left, bottom, alpha);
    }
    // Texels not yet filled always take the new block.
    for (int j = 0; j < block; ++j)
      for (int i = 0; i < block; ++i)
        if (site.mask.at<float>(j, i) == 0.0f) alpha.at<float>(j, i) = 1.0f;
  }
  return alpha;
}

cv::Mat PlanarSynthesis::OverlapError(const Site& site, const cv::Rect& sample_rect) const {
  cv::Mat error = cv::Mat::zeros(block_, block_, CV_32FC1);
  for (int c = 0; c < coefficient_planes_; ++c) {
    cv::Mat d = sample_planes_[static_cast<std::size_t>(c)](sample_rect) -
                site.out_block[static_cast<std::size_t>(c)];
    error += d.mul(d);
  }
  return error;
}

void PlanarSynthesis::BlendRamps(const cv::Mat& error, int left, int bottom, cv::Mat& alpha) {
  const int block = block_;
  for (int j = 0; j < block; ++j) {
    for (int i = 0; i < block; ++i) {
      float a = 1.0f;
      if (i < left) a = std::min(a, (i + 0.5f) / left);
      if (j >= block - bottom) a = std::min(a, (block - j - 0.5f) / bottom);
      alpha.at<float>(j, i) = a;
    }
  }
  // Seam texels: the 50 % line of each blend ramp.
  if (left > 0) {
    for (int j = 0; j < block; ++j) seam_sum_ += error.at<float>(j, left / 2), ++seam_texels_;
  }
  if (bottom > 0) {
    for (int i = 0; i < block; ++i)
      seam_sum_ += error.at<float>(block - 1 - bottom / 2, i), ++seam_texels_;
  }
}

void PlanarSynthesis::MinErrorCut(const cv::Mat& error, int left, int bottom, cv::Mat& alpha) {
  const int block = block_;
  if (left > 0) {
    const std::vector<int> cut = VerticalSeam(error(cv::Rect(0, 0, left, block)));
    for (int j = 0; j < block; ++j) {
      const int c = cut[static_cast<std::size_t>(j)];
      for (int i = 0; i < c; ++i) alpha.at<float>(j, i) = 0.0f;
      seam_sum_ += error.at<float>(j, c);
      ++seam_texels_;
    }
  }
  if (bottom > 0) {
    // Horizontal seam: the vertical seam of the transposed strip.
    cv::Mat strip = error(cv::Rect(0, block - bottom, block, bottom)).t();
    const std::vector<int> cut = VerticalSeam(strip);
    for (int i = 0; i < block; ++i) {
      const int r = block - bottom + cut[static_cast<std::size_t>(i)];  // new block above r
      for (int j = r + 1; j < block; ++j) alpha.at<float>(j, i) = 0.0f;
      seam_sum_ += error.at<float>(r, i);
      ++seam_texels_;
    }
  }
}

void PlanarSynthesis::Paste(const Site& site, const cv::Rect& sample_rect, const cv::Mat& alpha) {
  for (std::size_t c = 0; c < out_.size(); ++c) {
    cv::Mat dst = out_[c](site.out_rect);
    cv::Mat blended = sample_planes_[c](sample_rect).mul(alpha) + dst.mul(1.0 - alpha);
    blended.copyTo(dst);
  }
  filled_(site.out_rect).setTo(1.0f);
}

void PlanarSynthesis::Output() {
  result_.ptm = FromOrthonormalPlanes(out_, format_);
  if (constrained_) {
    result_.photo_rms_quilted = result_.photo_rms_corrected =
        PhotoConsistencyCorrection(result_.ptm, photos_, result_.photo_gains, 0);
    if (options_.correction_iterations > 0) {
      result_.photo_rms_corrected = PhotoConsistencyCorrection(
          result_.ptm, photos_, result_.photo_gains, options_.correction_iterations);
    }
  }
  result_.seam_cost_per_texel = seam_texels_ ? seam_sum_ / static_cast<double>(seam_texels_) : 0.0;
}

}  // namespace

PlanarSynthesisResult SynthesizePlanarPtm(const ptm::Ptm& sample,
                                          const std::vector<PlanarPhoto>& photos,
                                          const PlanarSynthesisOptions& options_in) {
  options_in.Check();
  const auto start = std::chrono::steady_clock::now();
  PlanarSynthesisResult result = PlanarSynthesis(sample, photos, options_in).Run();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

double PhotoConsistencyCorrection(ptm::Ptm& ptm, const std::vector<PlanarPhoto>& photos,
                                  const std::vector<double>& gains, int iterations) {
  if (photos.empty()) return 0.0;
  const int pw = photos[0].image.width, ph = photos[0].image.height;
  const int n_photos = static_cast<int>(photos.size());
  // Rows psi(l_n)^T = phi(l_n)^T L^-T of the orthonormal basis functions at each
  // light, and the minimum-norm solve da = L^-T A^T (A A^T + lambda I)^-1 t,
  // the same 6 x N matrix at every photo pixel (one light per photo).
  const Eigen::Matrix<double, 6, 6>& from = ptm::OrthonormalBasis::Hemisphere().FromOrthonormal();
  Eigen::MatrixXd a(n_photos, 6);
  for (int n = 0; n < n_photos; ++n) {
    const Eigen::Vector3d& l = photos[static_cast<std::size_t>(n)].light;
    const std::array<double, 6> phi = ptm::PtmBasis(l.x(), l.y());
    a.row(n) = Eigen::Map<const Eigen::Matrix<double, 1, 6>>(phi.data()) * from;
  }
  Eigen::MatrixXd aat = a * a.transpose();
  aat.diagonal().array() += 1e-4 * aat.trace() / n_photos;
  const Eigen::MatrixXd solve = from * a.transpose() * aat.inverse();  // 6 x N

  const int polys = ptm.NumPolynomials();
  const bool lrgb = ptm.format == ptm::PtmFormat::kLrgb;
  auto photo_mat = [&](int n) {
    const PlanarPhoto& p = photos[static_cast<std::size_t>(n)];
    return cv::Mat(ph, pw, CV_32FC3, const_cast<float*>(p.image.pixels.data()));
  };
  auto residuals = [&](std::vector<cv::Mat>& targets) {  // per photo, polys channels
    double sum = 0.0;
    cv::Mat colour_small;
    if (lrgb) {
      cv::Mat colour(ptm.height, ptm.width, CV_32FC3, ptm.colour.data());
      cv::resize(colour, colour_small, cv::Size(pw, ph), 0, 0, cv::INTER_AREA);
    }
    targets.assign(static_cast<std::size_t>(n_photos), cv::Mat());
    for (int n = 0; n < n_photos; ++n) {
      const double g = gains[static_cast<std::size_t>(n)];
      const std::vector<float> relit = ptm::Relight(ptm, photos[static_cast<std::size_t>(n)].light);
      cv::Mat full(ptm.height, ptm.width, CV_32FC3, const_cast<float*>(relit.data())), small;
      cv::resize(full, small, cv::Size(pw, ph), 0, 0, cv::INTER_AREA);
      const cv::Mat r = photo_mat(n) - small * g;  // RGB residual
      cv::Mat t(ph, pw, CV_32FC(polys));
      for (int y = 0; y < ph; ++y) {
        for (int x = 0; x < pw; ++x) {
          const cv::Vec3f rv = r.at<cv::Vec3f>(y, x);
          const float y_res = (rv[0] + rv[1] + rv[2]) / 3.0f;  // Y = mean of R, G, B
          sum += static_cast<double>(y_res) * y_res;
          float* tp = t.ptr<float>(y) + x * polys;
          if (lrgb) {
            const cv::Vec3f c = colour_small.at<cv::Vec3f>(y, x);
            const float y_colour = (c[0] + c[1] + c[2]) / 3.0f;
            tp[0] = y_colour > 1e-3f ? static_cast<float>(y_res / (g * y_colour)) : 0.0f;
          } else {
            for (int p = 0; p < 3; ++p) tp[p] = static_cast<float>(rv[p] / g);
          }
        }
      }
      targets[static_cast<std::size_t>(n)] = t;
    }
    return std::sqrt(sum / (static_cast<double>(pw) * ph * n_photos));
  };

  std::vector<cv::Mat> targets;
  double rms = residuals(targets);
  for (int it = 0; it < iterations; ++it) {
    for (int p = 0; p < polys; ++p) {
      // da per photo pixel for polynomial p, then bicubic to the texels.
      std::vector<cv::Mat> delta_small(6);
      for (cv::Mat& d : delta_small) d = cv::Mat::zeros(ph, pw, CV_32FC1);
      for (int y = 0; y < ph; ++y) {
        for (int x = 0; x < pw; ++x) {
          Eigen::VectorXd t(n_photos);
          for (int n = 0; n < n_photos; ++n)
            t[n] = targets[static_cast<std::size_t>(n)].ptr<float>(y)[x * polys + p];
          const Eigen::Matrix<double, 6, 1> da = solve * t;
          for (int i = 0; i < 6; ++i)
            delta_small[static_cast<std::size_t>(i)].at<float>(y, x) = static_cast<float>(da[i]);
        }
      }
      for (int i = 0; i < 6; ++i) {
        cv::Mat delta;
        cv::resize(delta_small[static_cast<std::size_t>(i)], delta, cv::Size(ptm.width, ptm.height),
                   0, 0, cv::INTER_CUBIC);
        for (int y = 0; y < ptm.height; ++y) {
          for (int x = 0; x < ptm.width; ++x) {
            const std::size_t texel = static_cast<std::size_t>(y) * ptm.width + x;
            ptm.Coefficients(texel, p)[i] += delta.at<float>(y, x);
          }
        }
      }
    }
    rms = residuals(targets);
  }
  return rms;
}

double NearestPatchEnergy(const ptm::Ptm& output, const ptm::Ptm& sample, int patch) {
  const int coefficient_planes = CoefficientPlanes(sample.format);
  const auto sample_all = ToOrthonormalPlanes(sample);
  const std::vector<cv::Mat> sample_planes(sample_all.begin(),
                                           sample_all.begin() + coefficient_planes);
  const cv::Mat energy = PlaneEnergy(sample_planes);
  const auto out_all = ToOrthonormalPlanes(output);
  const cv::Mat ones = cv::Mat::ones(patch, patch, CV_32FC1);
  double sum = 0.0;
  int count = 0;
  for (int y = 0; y + patch <= output.height; y += patch) {
    for (int x = 0; x + patch <= output.width; x += patch) {
      const cv::Mat ssd =
          MaskedSsd(sample_planes, energy,
                    Roi(out_all, cv::Rect(x, y, patch, patch), coefficient_planes), ones);
      double min_ssd;
      cv::minMaxLoc(ssd, &min_ssd);
      sum += min_ssd / (patch * patch);
      ++count;
    }
  }
  return count ? sum / count : 0.0;
}

}  // namespace texlume::synth
