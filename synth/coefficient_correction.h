#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/srgb.h"
#include "synth/detail_transfer.h"
#include "synth/material_sample.h"
#include "synth/mesh_synthesis.h"
#include "synth/triangle_engine.h"

namespace texlume::synth {

/// The PTM photo-consistency pass (beyond paper 003, as the planar synthesis's)
/// and detail transfer, as the engine's "correct" and "transfer detail" stages
/// for an LRGB sample.
///
/// Correct: per cell of the best view's grid (every view rectified on it), the
/// most probable change of the orthonormal luminance coefficients,
///   q = m + Sigma J^T (J Sigma J^T + s^2 I)^-1 (r + J (q0 - m)),
/// J_n the derivative of the displayed luminance under photo n's lights (sRGB,
/// gain and light mixture linearised at the current value), r_n the photo's
/// luminance minus the prediction (eq. 3's residual), Sigma the sample's own
/// coefficient covariance at the photo's density, m the prior mean (the patch
/// moved toward the sample's mean); low-frequency per-channel factors carry
/// the photos' chromaticity. Cells outside the triangle take their
/// neighbours' change.
///
/// Finish (detail transfer, synth/detail_transfer.h): per density level a face
/// was corrected at, the sample's DetailDictionary; each corrected patch's cells
/// matched to the sample points whose coarse windows are nearest.
class CoefficientCorrection : public PhotoCorrection {
 public:
  CoefficientCorrection(const PtmSample& sample, const MeshSynthesisOptions& options);
  ~CoefficientCorrection() override;

  void Correct(TriangleEngine& engine, std::size_t face, std::vector<RectifiedView>& views,
               const std::vector<RelitWindow>& relit) override;
  void Finish(TriangleEngine& engine, const std::vector<std::size_t>& faces,
              const ProgressCallback& progress) override;
  /// A distributed run: the face's correction level (its patch carries the rest).
  void SaveFace(std::size_t face, ByteWriter& out) const override;
  void LoadFace(TriangleEngine& engine, std::size_t face, ByteReader& in) override;

  /// Per density level, the detail bands the transferred patches read
  /// (MeshSynthesis::detail_bands).
  std::map<int, cv::Mat> TakeDetailBands() { return std::move(detail_bands_); }

  /// The prior of the pass at a density level: the mean and covariance of the
  /// reduced sample's orthonormal luminance coefficients.
  struct CoefficientPrior {
    Eigen::Matrix<double, 6, 1> mean;
    Eigen::Matrix<double, 6, 6> covariance;
    Eigen::Matrix<double, 6, 6> precision;  ///< covariance^-1
  };

 private:
  class PatchPass;
  const CoefficientPrior& PriorAt(int level);

  const PtmSample& sample_;
  const MeshSynthesisOptions& options_;
  std::map<int, CoefficientPrior> priors_;
  std::vector<int> correction_level_;  ///< per face: the grid's density level, -1 uncorrected
  std::map<int, std::unique_ptr<DetailDictionary>> dictionaries_;
  std::map<int, cv::Mat> detail_bands_;
};

/// One light's share of a texel's linear value in a channel, as PtmSample::Relight
/// relights it: the display value (luminance polynomial times colour) clamped to
/// [0, 1] and decoded from sRGB; when `slope` is given, d share / d display into it
/// (0 where clamped: black or white). The pass predicts the photos with it, a
/// call per light, channel and cell: inline.
inline double RelitLinearShare(double display, double* slope = nullptr) {
  if (slope) *slope = 0.0;
  if (display <= 0.0) return 0.0;  // black
  if (display >= 1.0) return 1.0;  // white: srgb::ToLinear(1) = 1
  const auto v = static_cast<float>(display);
  const float linear = srgb::ToLinear(v);
  if (slope) *slope = srgb::ToLinearSlope(v, linear);
  return linear;
}

}  // namespace texlume::synth
