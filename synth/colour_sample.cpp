#include "synth/colour_sample.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/check.h"
#include "core/errors.h"
#include "core/image_io.h"
#include "synth/channel_factor_correction.h"
#include "synth/planar_synthesis.h"
#include "synth/template_match.h"

namespace texlume::synth {
namespace {

// The luminance polynomial of a Lambertian texel in the display domain: the
// least-squares fit of l_z^(1/2.2) over light directions on a grid of
// azimuths and elevations from ptm::kHorizonElevationDeg to 90 degrees.
std::array<float, 6> LambertianLuminance() {
  std::vector<std::array<double, 6>> rows;
  std::vector<double> values;
  for (int e = 0; e <= 15; ++e) {
    const double elevation =
        (ptm::kHorizonElevationDeg + (90.0 - ptm::kHorizonElevationDeg) * e / 15.0) *
        std::numbers::pi / 180.0;
    for (int a = 0; a < 36; ++a) {
      const double azimuth = 2.0 * std::numbers::pi * a / 36.0;
      const double lu = std::cos(elevation) * std::cos(azimuth);
      const double lv = std::cos(elevation) * std::sin(azimuth);
      rows.push_back(ptm::PtmBasis(lu, lv));
      values.push_back(std::pow(std::sin(elevation), 1.0 / 2.2));
    }
  }
  Eigen::MatrixXd a(static_cast<Eigen::Index>(rows.size()), 6);
  Eigen::VectorXd b(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (int k = 0; k < 6; ++k)
      a(static_cast<Eigen::Index>(r), k) = rows[r][static_cast<std::size_t>(k)];
    b(static_cast<Eigen::Index>(r)) = values[r];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  std::array<float, 6> out;
  for (int k = 0; k < 6; ++k) out[static_cast<std::size_t>(k)] = static_cast<float>(x[k]);
  return out;
}

}  // namespace

ColourSample::ColourSample(const cv::Mat& display_rgb) {
  TEXLUME_CHECK(display_rgb.type() == CV_32FC3 && !display_rgb.empty(),
                "a colour sample is CV_32FC3 display RGB");
  cv::split(display_rgb, display_);
  linear_.resize(3);
  double sum = 0.0;
  for (std::size_t c = 0; c < 3; ++c) {
    linear_[c] = cv::Mat(display_[c].size(), CV_32FC1);
    for (int y = 0; y < linear_[c].rows; ++y)
      for (int x = 0; x < linear_[c].cols; ++x) {
        const float v = SrgbToLinear(display_[c].at<float>(y, x));
        linear_[c].at<float>(y, x) = v;
        sum += v;
      }
  }
  mean_linear_sum_ = sum / static_cast<double>(display_rgb.total());
}

void ColourSample::FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const {
  for (std::size_t c = 0; c < 3; ++c)
    out[c] =
        static_cast<float>(BilinearClamped(display_[c], sample_px.x() - 0.5, sample_px.y() - 0.5));
}

double ColourSample::LambertFactor(const FaceLighting& lighting) {
  double factor = lighting.response.ambient;
  for (const auto& [l, intensity] : lighting.lights)
    factor += intensity * std::max(0.0, l.z()) * lighting.response.FactorAt(l.z()) *
              lighting.response.ViewFactorAt(l, lighting.view_in_frame);
  return factor;
}

std::vector<cv::Mat> ColourSample::Relight(const ReducedPlanes& reduced,
                                           const FaceLighting& lighting, double gain) const {
  const double scale = gain * LambertFactor(lighting);
  // Cell by cell, as OpenCV's scaling multiplies (in floats, by the factor as a
  // float), so that any window of the sample is relit as the whole is.
  std::vector<cv::Mat> out(3);
  for (std::size_t c = 0; c < 3; ++c) {
    out[c] = cv::Mat(reduced.planes[c].size(), CV_32FC1);
    for (int y = 0; y < out[c].rows; ++y) {
      const float* in = reduced.planes[c].ptr<float>(y);
      float* relit = out[c].ptr<float>(y);
      for (int x = 0; x < out[c].cols; ++x) relit[x] = in[x] * static_cast<float>(scale);
    }
  }
  return out;
}

double ColourSample::RelitLinearSum(const FaceLighting& lighting, int cells) const {
  return mean_linear_sum_ * LambertFactor(lighting) * cells;
}

ptm::Ptm LambertianPtm(const cv::Mat& display_rgb) {
  TEXLUME_CHECK(display_rgb.type() == CV_32FC3, "a colour sample is CV_32FC3 display RGB");
  static const std::array<float, 6> kLuminance = LambertianLuminance();
  ptm::Ptm out;
  out.Resize(ptm::PtmFormat::kLrgb, display_rgb.cols, display_rgb.rows);
  for (int y = 0; y < display_rgb.rows; ++y)
    for (int x = 0; x < display_rgb.cols; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * display_rgb.cols + x;
      std::copy(kLuminance.begin(), kLuminance.end(), out.Coefficients(t, 0));
      const cv::Vec3f& c = display_rgb.at<cv::Vec3f>(y, x);
      for (int k = 0; k < 3; ++k) out.colour[t * 3 + static_cast<std::size_t>(k)] = c[k];
    }
  return out;
}

void ColourSynthesisOptions::Check() const {
  TriangleEngineOptions::Check();
  if (!(correction_noise > 0.0) || !std::isfinite(correction_noise))
    throw OptionError("correction noise must be > 0");
  if (!(correction_sigma > 0.0) || !std::isfinite(correction_sigma))
    throw OptionError("correction sigma must be > 0 photo pixels");
}

namespace {

// A face's linear factors as the PTM patch's display-domain per-channel gains
// (no additive change), on the factors' grid.
void FactorsAsChannelGains(const cv::Mat& factors, const Eigen::Vector2d& density,
                           TrianglePatch& patch) {
  if (factors.empty()) return;
  patch.correction.assign(6, cv::Mat());
  for (cv::Mat& m : patch.correction) m = cv::Mat::zeros(factors.size(), CV_32FC1);
  std::vector<cv::Mat> k;
  cv::split(factors, k);
  patch.channel_gain.assign(3, cv::Mat());
  for (std::size_t c = 0; c < 3; ++c) cv::pow(k[c], 1.0 / 2.2, patch.channel_gain[c]);
  patch.correction_density = density;
}

}  // namespace

MeshSynthesis SynthesizeMeshColour(const mesh::TriangleMesh& mesh,
                                   const sfm::Reconstruction& reconstruction,
                                   const sfm::VisibilityResult& visibility,
                                   const std::vector<MeshPhoto>& photos, const cv::Mat& display_rgb,
                                   const ColourSynthesisOptions& options,
                                   const ProgressCallback& progress, const FaceRegions* regions) {
  options.Check();
  const ColourSample sample(display_rgb);
  // The observed cells reach as far as the blend (W_e / 2), like the score's.
  ChannelFactorCorrection correction({options.correction_noise, options.correction_sigma,
                                      0.5 * options.strip * options.sample_texel_size});
  TriangleEngine engine(mesh, reconstruction, visibility, photos, sample, options,
                        options.photo_correction ? &correction : nullptr);
  MeshSynthesis result;
  if (regions) engine.DistributeOver(*regions);
  static_cast<TriangleSynthesis&>(result) = engine.Run(progress);
  if (result.rank_share_only) return result;  // rank 0 finishes
  result.format = ptm::PtmFormat::kLrgb;
  result.sample_planes = ToOrthonormalPlanes(LambertianPtm(display_rgb));
  const std::vector<cv::Mat>& factors = correction.factors();
  for (std::size_t f = 0; f < factors.size() && f < result.patches.size(); ++f)
    FactorsAsChannelGains(factors[f], correction.density()[f], result.patches[f]);
  return result;
}

}  // namespace texlume::synth
