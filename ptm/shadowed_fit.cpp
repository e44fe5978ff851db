#include "ptm/shadowed_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>

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

// FitShadowedPtm's steps, in order; each reports its progress.
class ShadowedFit {
 public:
  static constexpr std::string_view kStage = "fitting the PTM and its horizon";

  ShadowedFit(const std::vector<cv::Mat>& images, const std::vector<Eigen::Vector3d>& lights,
              const ShadowedFitOptions& options, const ProgressCallback& progress)
      : images_(images),
        lights_(lights),
        options_(options),
        progress_(progress),
        steps_(options.height_scales.size() + 2) {
    shadowing_.penumbra_rad = options.penumbra_deg * kDegree;
  }

  // An RGB PTM of every sample, whose normals (Malzbender et al. eq. 16) are
  // integrated into the relief's heights, in texel units.
  void IntegrateNormals() {
    Report();
    const Ptm all = FitPtmToLitSamples(images_, lights_, AllLit(lights_.size(), images_[0].total()),
                                       PtmFormat::kRgb, 6);
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
      Report();
      SelfShadowing trial = shadowing_;
      trial.horizon = HorizonAtScale(scale);
      const LitMask lit = LitSamples(trial.horizon, fit_lights, trial.penumbra_rad);
      const Ptm fit =
          FitPtmToLitSamples(fit_images, fit_lights, lit, options_.format, options_.min_lit_lights);
      trial.shadow_floor = ShadowFloor(fit, fit_images, fit_lights, lit);
      double error = 0;
      for (std::size_t k = 0; k < check_lights.size(); ++k)
        error += MeanSquaredError(RelightShadowed(fit, trial, check_lights[k]), check_images[k]);
      if (error < best_error) best_error = error, shadowing_.height_scale = scale;
    }
  }

  // The PTM of the samples the chosen horizon leaves lit, and the shadow floor.
  ShadowedPtm RefitLitSamples() {
    Report();
    ShadowedPtm out;
    shadowing_.horizon = HorizonAtScale(shadowing_.height_scale);
    const LitMask lit = LitSamples(shadowing_.horizon, lights_, shadowing_.penumbra_rad);
    out.ptm = FitPtmToLitSamples(images_, lights_, lit, options_.format, options_.min_lit_lights);
    shadowing_.shadow_floor = ShadowFloor(out.ptm, images_, lights_, lit);
    shadowing_.height_scale = ScaleForRefittedNormals(out.ptm);
    out.shadowing = std::move(shadowing_);
    if (progress_) progress_(kStage, steps_, steps_);
    return out;
  }

 private:
  // The refitted PTM's normals are steeper than the first fit's (its shadowed
  // samples are gone): the scale that takes their integrated heights to the chosen
  // relief by least squares, so that ShadowingOfPtm of the refitted PTM (and of an
  // atlas made of it) finds the horizon chosen here.
  double ScaleForRefittedNormals(const Ptm& refitted) const {
    const cv::Mat refitted_heights =
        HeightFromNormals(NormalMap(refitted), refitted.width, refitted.height);
    const double power = refitted_heights.dot(refitted_heights);
    if (!(power > 0.0)) return shadowing_.height_scale;
    return std::max(0.0, shadowing_.height_scale * heights_texels_.dot(refitted_heights) / power);
  }

  HorizonMap HorizonAtScale(double scale) const {
    return ComputeHorizonMap(heights_texels_ * scale, options_.sectors, options_.reach_texels);
  }
  void Report() {
    if (progress_) progress_(kStage, step_++, steps_);
  }

  const std::vector<cv::Mat>& images_;
  const std::vector<Eigen::Vector3d>& lights_;
  const ShadowedFitOptions& options_;
  const ProgressCallback& progress_;
  const std::size_t steps_;
  std::size_t step_ = 0;
  cv::Mat heights_texels_;
  SelfShadowing shadowing_;
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

Ptm FitPtmToLitSamples(const std::vector<cv::Mat>& images,
                       const std::vector<Eigen::Vector3d>& lights, const LitMask& lit,
                       PtmFormat format, int min_lit_lights) {
  const int width = images[0].cols, height = images[0].rows;
  Ptm out;
  out.Resize(format, width, height);
  const Eigen::Matrix<double, Eigen::Dynamic, 6> a = PtmLightMatrix(lights);
#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * width + x;
      int lit_count = 0;
      for (const auto& w : lit) lit_count += w[t] > 0.5f;
      const auto kept = [&](std::size_t k) {
        return lit_count < min_lit_lights || lit[k][t] > 0.5f;
      };
      const auto rgb = [&](std::size_t k) {
        const cv::Vec3f v = images[k].ptr<cv::Vec3f>(y)[x];
        return Eigen::Vector3d(v[0], v[1], v[2]);
      };
      // LRGB (fit.h): the luminance-weighted mean colour, largest channel 1; the
      // polynomial fits each sample's projection on it.
      Eigen::Vector3d colour = Eigen::Vector3d::Ones();
      if (format == PtmFormat::kLrgb) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (std::size_t k = 0; k < lights.size(); ++k)
          if (kept(k)) sum += rgb(k).mean() * rgb(k);
        if (sum.maxCoeff() > 1e-9) colour = sum / sum.maxCoeff();
        for (int c = 0; c < 3; ++c)
          out.colour[t * 3 + static_cast<std::size_t>(c)] = static_cast<float>(colour[c]);
      }
      const Eigen::Vector3d projection = colour / colour.squaredNorm();
      // Normal equations of eq. 1 over the kept samples, one right side per polynomial.
      Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 3> rhs = Eigen::Matrix<double, 6, 3>::Zero();
      for (std::size_t k = 0; k < lights.size(); ++k) {
        if (!kept(k)) continue;
        const Eigen::Matrix<double, 6, 1> row = a.row(static_cast<Eigen::Index>(k)).transpose();
        normal += row * row.transpose();
        const Eigen::Vector3d v = rgb(k);
        if (format == PtmFormat::kLrgb) {
          rhs.col(0) += row * v.dot(projection);
        } else {
          for (int c = 0; c < 3; ++c) rhs.col(c) += row * v[c];
        }
      }
      const Eigen::Matrix<double, 6, 3> coefficients = normal.ldlt().solve(rhs);
      for (int c = 0; c < out.NumPolynomials(); ++c)
        for (int i = 0; i < 6; ++i)
          out.Coefficients(t, c)[i] = static_cast<float>(coefficients(i, c));
    }
  return out;
}

std::vector<float> RelightShadowed(const Ptm& ptm, const SelfShadowing& shadowing,
                                   const Eigen::Vector3d& light) {
  if (shadowing.horizon.width != ptm.width || shadowing.horizon.height != ptm.height)
    throw std::invalid_argument("a " + std::to_string(shadowing.horizon.width) + " x " +
                                std::to_string(shadowing.horizon.height) + " horizon map for a " +
                                std::to_string(ptm.width) + " x " + std::to_string(ptm.height) +
                                " PTM");
  const Eigen::Vector3d l = light.normalized();
  std::vector<float> rgb = Relight(ptm, l);
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(ptm.NumTexels()); ++i) {
    const auto t = static_cast<std::size_t>(i);
    const auto keep = static_cast<float>(shadowing.LightFactor(t, l));
    for (std::size_t c = 0; c < 3; ++c) {
      float& value = rgb[t * 3 + c];
      value = srgb::FromLinear(srgb::ToLinear(value) * keep);
    }
  }
  return rgb;
}

std::vector<float> RelightShadowed(const ShadowedPtm& shadowed, const Eigen::Vector3d& light) {
  return RelightShadowed(shadowed.ptm, shadowed.shadowing, light);
}

ShadowedPtm FitShadowedPtm(const std::vector<cv::Mat>& images,
                           const std::vector<Eigen::Vector3d>& lights,
                           const ShadowedFitOptions& options, const ProgressCallback& progress) {
  options.Check();
  if (images.size() != lights.size() || lights.size() < 8)
    throw InputError(
        "capture", std::to_string(lights.size()) + " lights and " + std::to_string(images.size()) +
                       " images: a shadowed fit needs at least 8 of each, one per light");
  for (const cv::Mat& image : images)
    if (image.type() != CV_32FC3 || image.size() != images[0].size())
      throw InputError("capture", "the images must all be float RGB of one size");
  ShadowedFit fit(images, lights, options, progress);
  fit.IntegrateNormals();
  fit.ChooseHeightScale();
  return fit.RefitLitSamples();
}

SelfShadowing ShadowingOfPtm(const Ptm& ptm, const SelfShadowing& sample, int reach_texels,
                             const cv::Mat& charts) {
  SelfShadowing out;
  out.height_scale = sample.height_scale;
  out.shadow_floor = sample.shadow_floor;
  out.penumbra_rad = sample.penumbra_rad;
  const cv::Mat heights_texels = HeightFromNormals(NormalMap(ptm), ptm.width, ptm.height);
  out.horizon = ComputeHorizonMap(heights_texels * sample.height_scale, sample.horizon.sectors,
                                  reach_texels, charts);
  return out;
}

}  // namespace texlume::ptm
