#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "btf/btf.h"
#include "synth/material_sample.h"

namespace texlume::synth {

/// A BTF sample (paper 004 §III), f(x, v, l) = sum_i g_i(x) p_i(v, l): features
/// are the geometry maps g_i, which a frame rotation leaves as they are (it
/// turns the directions p is evaluated at); mesostructure is cut, never
/// blended; relit in the linear domain with the view of each photo.
class BtfSample : public MaterialSample {
 public:
  explicit BtfSample(const btf::BtfFactorisation& btf);

  std::string Name() const override { return "BTF"; }
  int Width() const override { return btf_.width; }
  int Height() const override { return btf_.height; }
  const std::vector<cv::Mat>& FeaturePlanes() const override { return geometry_; }
  void FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const override;
  void TurnFeatures(const Unfolding&, float*) const override {}
  bool Blendable() const override { return false; }
  bool ViewDependent() const override { return true; }
  PhotoDomain Domain() const override { return PhotoDomain::kLinear; }
  /// sum_i g_i A_i with A = sum_lights I p(v, l) (n x 3; Appearance).
  std::vector<cv::Mat> Relight(const ReducedPlanes& reduced, const FaceLighting& lighting,
                               double gain) const override;
  double RelitLinearSum(const FaceLighting& lighting, int cells) const override;

  /// A = sum over the lights above the face of I p(v, l) (n x 3), the view
  /// too above it; zero otherwise.
  Eigen::MatrixX3f Appearance(const FaceLighting& lighting) const;
  const btf::BtfFactorisation& btf() const { return btf_; }

 protected:
  /// The geometry maps: the BTF is linear in g, so reducing g equals reducing
  /// the relit image.
  const std::vector<cv::Mat>& RelightPlanes() const override { return geometry_; }

 private:
  const btf::BtfFactorisation& btf_;
  std::vector<cv::Mat> geometry_;
  Eigen::VectorXf mean_g_;
};

}  // namespace texlume::synth
