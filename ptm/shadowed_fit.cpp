#include "ptm/shadowed_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/errors.h"
#include "core/srgb.h"

namespace texlume::ptm {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

using LitMask = std::vector<std::vector<float>>;

// Per light, 1 where the horizon leaves the texel more than half lit.
LitMask LitSamples(const HorizonMap& horizon, const std::vector<Eigen::Vector3d>& lights,
                   double penumbra_rad) {
  LitMask lit(lights.size(), std::vector<float>(horizon.NumTexels()));
  for (std::size_t k = 0; k < lights.size(); ++k)
    for (std::size_t t = 0; t < horizon.NumTexels(); ++t)
      lit[k][t] = HorizonVisibility(horizon, t, lights[k], penumbra_rad) > 0.5 ? 1.f : 0.f;
  return lit;
}

LitMask AllLit(std::size_t lights, std::size_t texels) {
  return LitMask(lights, std::vector<float>(texels, 1.f));
}

// The median ratio of the shadowed samples' linear light to the lit fit's (every
// third texel: the median needs no more).
double ShadowFloor(const Ptm& lit_fit, const std::vector<cv::Mat>& images,
                   const std::vector<Eigen::Vector3d>& lights, const LitMask& lit) {
  std::vector<double> ratios;
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const std::vector<float> fit = Relight(lit_fit, lights[k]);
    for (std::size_t t = 0; t < lit_fit.NumTexels(); t += 3) {
      if (lit[k][t] > 0.5f) continue;
      const auto* observed_rgb =
          images[k].ptr<cv::Vec3f>(static_cast<int>(t / static_cast<std::size_t>(lit_fit.width)));
      const cv::Vec3f v = observed_rgb[t % static_cast<std::size_t>(lit_fit.width)];
      double observed = 0, predicted = 0;
      for (int c = 0; c < 3; ++c) {
        observed += srgb::ToLinear(v[c]);
        predicted += srgb::ToLinear(fit[t * 3 + static_cast<std::size_t>(c)]);
      }
      if (predicted > 1e-3) ratios.push_back(observed / predicted);
    }
  }
  if (ratios.empty()) return 1.0;
  const auto middle = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
  std::nth_element(ratios.begin(), middle, ratios.end());
  return std::clamp(*middle, 0.0, 1.0);
}

double MeanSquaredError(const std::vector<float>& rgb, const cv::Mat& image) {
  double sum = 0;
  for (int y = 0; y < image.rows; ++y) {
    const auto* row = image.ptr<cv::Vec3f>(y);
    for (int x = 0; x < image.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double d =
            rgb[(static_cast<std::size_t>(y) * image.cols + x) * 3 + static_cast<std::size_t>(c)] -
            row[x][c];
        sum += d * d;
      }
  }
  return sum / (static_cast<double>(image.total()) * 3.0);
}

// FitShadowedPtm's steps, in order.
class ShadowedFit {
 public:
  ShadowedFit(const std::vector<cv::Mat>& images, const std::vector<Eigen::Vector3d>& lights,
              const ShadowedFitOptions& options)
      : images_(images),
        lights_(lights),
        options_(options),
        penumbra_rad_(options.penumbra_deg * kDegree) {}

  // An RGB PTM of every sample, whose normals (Malzbender et al. eq. 16) are
  // integrated into the relief's heights, in texel units.
  void IntegrateNormals() {
    const Ptm all =
        FitRgbPtmToLitSamples(images_, lights_, AllLit(lights_.size(), images_[0].total()), 6);
    heights_texels_ = HeightFromNormals(NormalMap(all), all.width, all.height);
  }

  // The height scale whose shadowed relight best predicts every fourth light
  // (from the second on) when fitted to the others.
  void ChooseHeightScale() {
    std::vector<cv::Mat> fit_images, check_images;
    std::vector<Eigen::Vector3d> fit_lights, check_lights;
    for (std::size_t k = 0; k < lights_.size(); ++k) {
      (k % 4 == 1 ? check_images : fit_images).push_back(images_[k]);
      (k % 4 == 1 ? check_lights : fit_lights).push_back(lights_[k]);
    }
    double best_error = std::numeric_limits<double>::infinity();
    for (const double scale : options_.height_scales) {
      const HorizonMap horizon = HorizonAtScale(scale);
      const LitMask lit = LitSamples(horizon, fit_lights, penumbra_rad_);
      const Ptm fit = FitRgbPtmToLitSamples(fit_images, fit_lights, lit, options_.min_lit_lights);
      const double floor = ShadowFloor(fit, fit_images, fit_lights, lit);
      double error = 0;
      for (std::size_t k = 0; k < check_lights.size(); ++k)
        error += MeanSquaredError(
            RelightShadowed(fit, horizon, check_lights[k], floor, penumbra_rad_), check_images[k]);
      if (error < best_error) best_error = error, result_.height_scale = scale;
    }
  }

  // The PTM of the samples the chosen horizon leaves lit, and the shadow floor.
  ShadowedPtm RefitLitSamples() {
    result_.horizon = HorizonAtScale(result_.height_scale);
    const LitMask lit = LitSamples(result_.horizon, lights_, penumbra_rad_);
    result_.ptm = FitRgbPtmToLitSamples(images_, lights_, lit, options_.min_lit_lights);
    result_.shadow_floor = ShadowFloor(result_.ptm, images_, lights_, lit);
    result_.penumbra_rad = penumbra_rad_;
    return std::move(result_);
  }

 private:
  HorizonMap HorizonAtScale(double scale) const {
    return ComputeHorizonMap(heights_texels_ * scale, options_.sectors, options_.reach_texels);
  }

  const std::vector<cv::Mat>& images_;
  const std::vector<Eigen::Vector3d>& lights_;
  const ShadowedFitOptions& options_;
  const double penumbra_rad_;
  cv::Mat heights_texels_;
  ShadowedPtm result_;
};

}  // namespace

void ShadowedFitOptions::Check() const {
  if (sectors < 4 || sectors > 64) throw OptionError("horizon sectors must be in [4, 64]");
  if (reach_texels < 1 || reach_texels > 4096)
    throw OptionError("horizon reach must be in [1, 4096] texels");
  if (!(penumbra_deg > 0.0 && penumbra_deg <= 45.0))
    throw OptionError("penumbra must be in (0, 45] degrees");
  if (height_scales.empty()) throw OptionError("height_scales must not be empty");
  for (const double s : height_scales)
    if (!(s >= 0.0 && s <= 100.0)) throw OptionError("height scales must be in [0, 100]");
  if (min_lit_lights < 6) throw OptionError("min_lit_lights must be >= 6");
}

Ptm FitRgbPtmToLitSamples(const std::vector<cv::Mat>& images,
                          const std::vector<Eigen::Vector3d>& lights, const LitMask& lit,
                          int min_lit_lights) {
  const int width = images[0].cols, height = images[0].rows;
  Ptm out;
  out.Resize(PtmFormat::kRgb, width, height);
  const Eigen::Matrix<double, Eigen::Dynamic, 6> a = PtmLightMatrix(lights);
#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * width + x;
      int lit_count = 0;
      for (const auto& w : lit) lit_count += w[t] > 0.5f;
      // Normal equations of eq. 1 over the kept samples, one right side per channel.
      Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 3> rhs = Eigen::Matrix<double, 6, 3>::Zero();
      for (std::size_t k = 0; k < lights.size(); ++k) {
        if (lit_count >= min_lit_lights && lit[k][t] < 0.5f) continue;
        const Eigen::Matrix<double, 6, 1> row = a.row(static_cast<Eigen::Index>(k)).transpose();
        normal += row * row.transpose();
        const cv::Vec3f v = images[k].ptr<cv::Vec3f>(y)[x];
        for (int c = 0; c < 3; ++c) rhs.col(c) += row * static_cast<double>(v[c]);
      }
      const Eigen::Matrix<double, 6, 3> coefficients = normal.ldlt().solve(rhs);
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 6; ++i)
          out.Coefficients(t, c)[i] = static_cast<float>(coefficients(i, c));
    }
  return out;
}

std::vector<float> RelightShadowed(const Ptm& ptm, const HorizonMap& horizon,
                                   const Eigen::Vector3d& light, double shadow_floor,
                                   double penumbra_rad) {
  std::vector<float> rgb = Relight(ptm, light);
  for (std::size_t t = 0; t < ptm.NumTexels(); ++t) {
    const double v = HorizonVisibility(horizon, t, light.normalized(), penumbra_rad);
    const auto keep = static_cast<float>(v + (1.0 - v) * shadow_floor);
    for (std::size_t c = 0; c < 3; ++c) {
      float& value = rgb[t * 3 + c];
      value = srgb::FromLinear(srgb::ToLinear(value) * keep);
    }
  }
  return rgb;
}

std::vector<float> RelightShadowed(const ShadowedPtm& shadowed, const Eigen::Vector3d& light) {
  return RelightShadowed(shadowed.ptm, shadowed.horizon, light, shadowed.shadow_floor,
                         shadowed.penumbra_rad);
}

ShadowedPtm FitShadowedPtm(const std::vector<cv::Mat>& images,
                           const std::vector<Eigen::Vector3d>& lights,
                           const ShadowedFitOptions& options) {
  options.Check();
  if (images.size() != lights.size() || lights.size() < 8)
    throw InputError(
        "capture", std::to_string(lights.size()) + " lights and " + std::to_string(images.size()) +
                       " images: a shadowed fit needs at least 8 of each, one per light");
  for (const cv::Mat& image : images)
    if (image.type() != CV_32FC3 || image.size() != images[0].size())
      throw InputError("capture", "the images must all be float RGB of one size");
  ShadowedFit fit(images, lights, options);
  fit.IntegrateNormals();
  fit.ChooseHeightScale();
  return fit.RefitLitSamples();
}

}  // namespace texlume::ptm
