#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "ptm/ptm.h"
#include "synth/material_sample.h"
#include "synth/mesh_synthesis.h"

namespace texlume::synth {

/// A colour sample: an ordinary photo of the material (no RTI capture). Its
/// features are the display RGB planes (image quilting's distance); a frame
/// rotation leaves them as they are; values may be blended. Under a face's
/// lighting it is Lambertian, relit in the linear domain,
///   f = g * lin(c) * (ambient + sum_lights I max(0, l_z) r(l_z)),
/// so the photos' shading is absorbed by the gain g and the Lambertian factor;
/// what the sample cannot show (relief, highlights) the photo-consistency
/// factors and the PTM it is baked into approximate.
class ColourSample : public MaterialSample {
 public:
  /// `display_rgb`: CV_32FC3, R G B display (sRGB-encoded) values in [0, 1].
  explicit ColourSample(const cv::Mat& display_rgb);

  std::string Name() const override { return "colour"; }
  int Width() const override { return display_[0].cols; }
  int Height() const override { return display_[0].rows; }
  const std::vector<cv::Mat>& FeaturePlanes() const override { return display_; }
  void FeaturesAt(const Eigen::Vector2d& sample_px, float* out) const override;
  void TurnFeatures(const Unfolding&, float*) const override {}
  bool Blendable() const override { return true; }
  bool ViewDependent() const override { return false; }
  PhotoDomain Domain() const override { return PhotoDomain::kLinear; }
  std::vector<cv::Mat> Relight(const ReducedPlanes& reduced, const FaceLighting& lighting,
                               double gain) const override;
  double RelitLinearSum(const FaceLighting& lighting, int cells) const override;

  /// ambient + sum_lights I max(0, l_z) r(l_z): the Lambertian factor of a
  /// face's lighting (r and ambient: FaceLighting::response).
  static double LambertFactor(const FaceLighting& lighting);

 protected:
  /// Linear RGB: the Lambertian relighting is linear in it.
  const std::vector<cv::Mat>& RelightPlanes() const override { return linear_; }

 private:
  std::vector<cv::Mat> display_, linear_;
  double mean_linear_sum_ = 0.0;  ///< mean over texels of lin(R) + lin(G) + lin(B)
};

/// The colour sample as an LRGB PTM, as RTI tools would fit a Lambertian
/// surface: per texel its display colour, and one luminance polynomial for all
/// texels, the least-squares fit of l_z^(1 / 2.2) (the display-domain
/// Lambertian shading) over light directions from 15 to 90 degrees of
/// elevation (paper 003 eq. 1-2). Texture, render, view and export then treat
/// it as any PTM.
ptm::Ptm LambertianPtm(const cv::Mat& display_rgb);

/// Settings of SynthesizeMeshColour: the engine's, and the photo-consistency
/// factors (ChannelFactorCorrection).
struct ColourSynthesisOptions : TriangleEngineOptions {
  bool photo_correction = true;
  double correction_noise = 0.05;  ///< lambda, > 0
  double correction_sigma = 2.0;   ///< photo cells, > 0
  void Check() const;
};

/// Per-triangle image-constrained quilting of a colour sample (the
/// TriangleEngine with a ColourSample and ChannelFactorCorrection), returned
/// as a PTM synthesis of LambertianPtm(display_rgb) so that it is blended,
/// baked into atlases and exported as PTM models are: each corrected face
/// carries its factors (display domain, lin^(1/2.2)) as the per-channel gains
/// of MeshSynthesis. Throws as SynthesizeMeshPtm.
/// `regions`: a distributed run (TriangleEngine::DistributeOver); on ranks other than
/// 0 the result is only this rank's share (rank_share_only).
MeshSynthesis SynthesizeMeshColour(const mesh::TriangleMesh& mesh,
                                   const sfm::Reconstruction& reconstruction,
                                   const sfm::VisibilityResult& visibility,
                                   const std::vector<MeshPhoto>& photos, const cv::Mat& display_rgb,
                                   const ColourSynthesisOptions& options,
                                   const ProgressCallback& progress = {},
                                   const FaceRegions* regions = nullptr);

}  // namespace texlume::synth
