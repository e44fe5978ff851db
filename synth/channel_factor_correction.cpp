#include "synth/channel_factor_correction.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace texlume::synth {

namespace {

// The model seen through the photo's blur reads 3 sigma around the patch.
int BlurMarginCells(const RectifiedView& view) {
  return static_cast<int>(std::ceil(3.0 * view.blur_cells));
}

}  // namespace

int ChannelFactorCorrection::RelitMarginCells(const RectifiedView& view) const {
  return BlurMarginCells(view) + 2;
}

ChannelFactorCorrection::OnGrid ChannelFactorCorrection::ToGrid(const TrianglePatch& patch,
                                                                const RectifiedView& view,
                                                                const ReducedPlanes& red,
                                                                const RelitWindow& relit,
                                                                cv::Size grid) const {
  OnGrid g;
  const cv::Size size = view.mask.size();
  // The placed patch relit under the view: its cell i is at reduced-sample
  // position sample_x rx + i (pixel centres at integers), in the window at origin.
  const cv::Point2f centre(
      static_cast<float>(patch.sample_x * red.rx + (size.width - 1) * 0.5 - relit.origin.x),
      static_cast<float>(patch.sample_y * red.ry + (size.height - 1) * 0.5 - relit.origin.y));
  g.wide = view.wide_mask;
  g.inside = view.mask;
  for (std::size_t ch = 0; ch < 3; ++ch) {
    // The model as the photo sees it: through the photo's blur
    // (synth/photo_blur.h), over the relit sample around the patch too.
    const int margin = BlurMarginCells(view);
    cv::Mat wide;
    cv::getRectSubPix(relit.planes[ch], size + cv::Size(2 * margin, 2 * margin), centre, wide);
    if (view.blur_cells > 0.0) cv::GaussianBlur(wide, wide, cv::Size(), view.blur_cells);
    g.model[ch] = wide(cv::Rect(cv::Point(margin, margin), size)).clone();
    g.photo[ch] = view.planes[ch];
  }
  if (size != grid) {
    for (std::size_t ch = 0; ch < 3; ++ch) {
      cv::resize(g.model[ch], g.model[ch], grid, 0, 0, cv::INTER_AREA);
      cv::resize(g.photo[ch], g.photo[ch], grid, 0, 0, cv::INTER_AREA);
    }
    cv::resize(g.wide, g.wide, grid, 0, 0, cv::INTER_AREA);
    cv::resize(g.inside, g.inside, grid, 0, 0, cv::INTER_AREA);
  }
  return g;
}

cv::Mat ChannelFactorCorrection::ChannelFactors(const cv::Mat& num, const cv::Mat& den,
                                                const cv::Mat& observed, double observed_sum,
                                                const cv::Mat& weight,
                                                const cv::Mat& wide_weight) const {
  const double sigma = options_.sigma;
  const double mu = cv::sum(den)[0] / observed_sum;  // mean m^2 per observation
  const double prior = options_.noise * std::max(mu, 1e-12);
  cv::Mat raw;
  cv::divide(num + prior * observed, den + prior * observed + 1e-30, raw);
  // raw * observed is 0 where nothing is observed: normalised smoothing.
  const cv::Mat weighted = raw.mul(observed);
  cv::Mat smooth, wide;
  cv::GaussianBlur(weighted, smooth, cv::Size(), sigma);
  cv::GaussianBlur(weighted, wide, cv::Size(), 4.0 * sigma);
  cv::Mat k(observed.size(), CV_32FC1);
  for (int j = 0; j < k.rows; ++j)
    for (int i = 0; i < k.cols; ++i) {
      float v = 1.0f;
      if (weight.at<float>(j, i) > 0.05f)
        v = smooth.at<float>(j, i) / weight.at<float>(j, i);
      else if (wide_weight.at<float>(j, i) > 0.01f)
        v = wide.at<float>(j, i) / wide_weight.at<float>(j, i);
      k.at<float>(j, i) = std::clamp(v, 0.2f, 5.0f);
    }
  return k;
}

void ChannelFactorCorrection::Correct(TriangleEngine& engine, std::size_t face,
                                      std::vector<RectifiedView>& views,
                                      const std::vector<RelitWindow>& relit) {
  const std::size_t num_faces = engine.result().patches.size();
  if (factors_.size() != num_faces) {
    factors_.resize(num_faces);
    density_.assign(num_faces, Eigen::Vector2d::Ones());
  }
  const TrianglePatch& patch = engine.result().patches[face];
  const cv::Size grid = views[0].mask.size();
  std::array<cv::Mat, 3> num, den;
  for (std::size_t ch = 0; ch < 3; ++ch) {
    num[ch] = cv::Mat::zeros(grid, CV_32FC1);
    den[ch] = cv::Mat::zeros(grid, CV_32FC1);
  }
  cv::Mat observed = cv::Mat::zeros(grid, CV_32FC1);
  std::vector<OnGrid> on_grid;
  for (std::size_t r = 0; r < views.size(); ++r) {
    const OnGrid& g = on_grid.emplace_back(
        ToGrid(patch, views[r], engine.sample().Reduced(views[r].level), relit[r], grid));
    for (std::size_t ch = 0; ch < 3; ++ch) {
      num[ch] += g.model[ch].mul(g.photo[ch]).mul(g.wide);
      den[ch] += g.model[ch].mul(g.model[ch]).mul(g.wide);
    }
    observed += g.wide;
  }
  const double observed_sum = cv::sum(observed)[0];
  if (!(observed_sum > 0.0)) return;
  // The observed cells smoothed once for the three channels.
  cv::Mat weight, wide_weight;
  cv::GaussianBlur(observed, weight, cv::Size(), options_.sigma);
  cv::GaussianBlur(observed, wide_weight, cv::Size(), 4.0 * options_.sigma);
  std::vector<cv::Mat> k(3);
  for (std::size_t ch = 0; ch < 3; ++ch)
    k[ch] = ChannelFactors(num[ch], den[ch], observed, observed_sum, weight, wide_weight);
  for (const OnGrid& g : on_grid)
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const cv::Mat before = g.model[ch] - g.photo[ch];
      const cv::Mat after = g.model[ch].mul(k[ch]) - g.photo[ch];
      residual_quilted_ += cv::sum(before.mul(before).mul(g.inside))[0];
      residual_corrected_ += cv::sum(after.mul(after).mul(g.inside))[0];
      residual_count_ += cv::sum(g.inside)[0];
    }
  cv::merge(k, factors_[face]);
  const ReducedPlanes& grid_level = engine.sample().Reduced(views[0].level);
  density_[face] = Eigen::Vector2d(grid_level.rx, grid_level.ry);
}

void ChannelFactorCorrection::SaveFace(std::size_t face, ByteWriter& out) const {
  const bool kept = face < factors_.size();
  out.PutMat(kept ? factors_[face] : cv::Mat());
  out.Put(kept ? density_[face].x() : 1.0), out.Put(kept ? density_[face].y() : 1.0);
}

void ChannelFactorCorrection::LoadFace(TriangleEngine& engine, std::size_t face, ByteReader& in) {
  const std::size_t num_faces = engine.result().patches.size();
  if (factors_.size() != num_faces) {
    factors_.resize(num_faces);
    density_.resize(num_faces, Eigen::Vector2d::Ones());
  }
  factors_[face] = in.GetMat();
  density_[face].x() = in.Get<double>();
  density_[face].y() = in.Get<double>();
}

void ChannelFactorCorrection::SaveSums(ByteWriter& out) const {
  out.Put(residual_quilted_), out.Put(residual_corrected_), out.Put(residual_count_);
}

void ChannelFactorCorrection::AddSums(ByteReader& in) {
  residual_quilted_ += in.Get<double>();
  residual_corrected_ += in.Get<double>();
  residual_count_ += in.Get<double>();
}

double ChannelFactorCorrection::RmsQuilted() const {
  return residual_count_ > 0 ? std::sqrt(residual_quilted_ / residual_count_) : 0.0;
}

double ChannelFactorCorrection::RmsCorrected() const {
  return residual_count_ > 0 ? std::sqrt(residual_corrected_ / residual_count_) : 0.0;
}

}  // namespace texlume::synth
