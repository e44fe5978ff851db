#include "synth/btf_sample.h"

#include <algorithm>

#include "synth/template_match.h"

namespace texlume::synth {
namespace {

// Geometry maps as CV_32FC1 planes (for reductions and FFT matching).
std::vector<cv::Mat> GeometryPlanes(const btf::BtfFactorisation& s) {
  std::vector<cv::Mat> planes(static_cast<std::size_t>(s.Components()));
  for (int i = 0; i < s.Components(); ++i) {
    cv::Mat& m = planes[static_cast<std::size_t>(i)];
    m = cv::Mat(s.height, s.width, CV_32FC1);
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x)
        m.at<float>(y, x) = s.geometry(static_cast<Eigen::Index>(y) * s.width + x, i);
  }
  return planes;
}

}  // namespace

BtfSample::BtfSample(const btf::BtfFactorisation& btf)
    : btf_(btf),
      geometry_(GeometryPlanes(btf)),
      mean_g_(btf.geometry.colwise().mean().transpose()) {}

void BtfSample::FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const {
  btf::SampleGeometry(btf_, sample_px, out);
}

Eigen::MatrixX3f BtfSample::Appearance(const FaceLighting& lighting) const {
  const Eigen::Vector3d& v = lighting.view_in_frame;
  if (v.z() <= 0.0) return Eigen::MatrixX3f::Zero(btf_.Components(), 3);
  return btf::AppearanceUnder(btf_, v, lighting.lights, lighting.response);
}

std::vector<cv::Mat> BtfSample::Relight(const ReducedPlanes& r, const FaceLighting& lighting,
                                        double gain) const {
  const Eigen::MatrixX3f a = Appearance(lighting);
  std::vector<cv::Mat> out(3);
  for (int ch = 0; ch < 3; ++ch) {
    cv::Mat& m = out[static_cast<std::size_t>(ch)];
    m = cv::Mat::zeros(r.planes[0].size(), CV_32FC1);
    for (int i = 0; i < btf_.Components(); ++i)
      cv::scaleAdd(r.planes[static_cast<std::size_t>(i)], static_cast<double>(a(i, ch)) * gain, m,
                   m);
  }
  return out;
}

double BtfSample::RelitLinearSum(const FaceLighting& lighting, int cells) const {
  return (mean_g_.transpose() * Appearance(lighting)).sum() * cells;
}

}  // namespace texlume::synth
