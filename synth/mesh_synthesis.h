#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

#include "core/progress.h"
#include "mesh/mesh.h"
#include "ptm/ptm.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"
#include "synth/triangle_engine.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {

/// Settings of SynthesizeMeshPtm (paper 003 Algorithm 2).
struct MeshSynthesisOptions : TriangleEngineOptions {
  /// Photo-consistency pass per triangle (beyond the paper, as in the planar
  /// synthesis): Gauss-Newton rounds of the most probable change of the
  /// luminance coefficients (a Gaussian prior with the sample's own coefficient
  /// covariance at the photo's density) that makes the patch, relit under each
  /// constraint photo's lights, equal the rectified photos at their density.
  /// 0 = off. [0, 5]. LRGB only.
  int correction_iterations = 2;
  /// The additive luminance change above.
  bool additive_correction = true;
  /// Photo noise of that estimate, as a share of the variance the prior predicts
  /// at the photo pixel: small trusts the photos, large keeps the sample. > 0.
  double correction_noise = 0.1;
  /// Prior mean of that estimate: the quilted patch's coefficients moved this
  /// share of the way to the sample's mean at the photo's density. The photos
  /// fix only the coefficient directions their lights see; in the others the
  /// quilted patch keeps its own structure, right only as far as the patch
  /// matches the object. 0 = the quilted patch, 1 = the mean; < 0 (default):
  /// estimated per patch as 1 - rho, rho in [0, 1] the share of the patch's
  /// departure from the mean that the photos confirm where they see it.
  /// [0, 1] or < 0.
  double correction_prior_shrink = -1.0;
  /// Low-frequency per-channel factors normalised to keep the luminance
  /// (chromaticity: stains, colour), before the additive change.
  bool channel_correction = true;
  /// Smoothing of the per-channel factors, in photo pixels (Gaussian sigma). > 0.
  double correction_sigma = 2.0;
  /// Detail transfer after the photo-consistency pass: the detail finer than
  /// the photo is taken from the sample where the sample's coarse coefficients
  /// best match the corrected ones (a 3 x 3 window of photo cells), so that it
  /// follows the photo's structure rather than the quilted patch's.
  bool detail_transfer = true;
  /// How far past its triangle the model reads a patch, in texels: the atlas's
  /// gutter ring, and half the blend strip (W_e / 2) into a neighbour's patch (the
  /// main job sets it from its atlas options: pipeline::SynthesisOptionsOf).
  /// Detail transfer matches only the cells such reads take (CellsReadWithin);
  /// the others keep the patch's own detail. < 0: every cell.
  double detail_reach_texels = -1.0;

  /// The engine's checks, then the photo-consistency pass's.
  void Check() const;
};

/// The per-triangle PTM synthesis: the engine's patches and unfoldings, the
/// sample's orthonormal planes they reference, and the detail bands the detail
/// transfer reads.
struct MeshSynthesis : TriangleSynthesis {
  ptm::PtmFormat format = ptm::PtmFormat::kLrgb;
  std::vector<cv::Mat> sample_planes;  ///< orthonormal coefficients (+ LRGB colour)
  /// Per photo-density level: the sample's detail band, its planes minus their
  /// reduction to that density brought back to full size (all planes, texels;
  /// interleaved, CV_32FC(planes): a texel's values side by side for the bake).
  std::map<int, cv::Mat> detail_bands;
  /// Faces whose values another engine supplies in place of their patch (the
  /// main job's graph-cut fill of the faces no photo sees, quilt/unseen_fill.h):
  /// per face whether it does (empty: none), and its values at a point of the
  /// face frame (all planes, orthonormal, face frame; false where it has none,
  /// and the patch is read).
  std::vector<bool> filled;
  std::function<bool(int face, const Eigen::Vector2d& p_in_frame, float* planes_out)> fill;

  /// Most planes a texel has (RGB: 18 coefficients; LRGB: 6 + 3 colour).
  static constexpr std::size_t kMaxPlanes = 18;
  /// Number of coefficient planes (6 LRGB, 18 RGB); colour planes follow for LRGB.
  int CoefficientPlanes() const { return format == ptm::PtmFormat::kLrgb ? 6 : 18; }
  /// The face's own patch at frame point p (world units), bilinear, or its fill;
  /// false outside it.
  bool SamplePatch(int face, const Eigen::Vector2d& p_in_frame, float* planes_out) const;
  /// Blended value (paper 003 Fig. 4) at a point of the face: near an edge, the
  /// neighbour's patch unfolded across it and moved into this frame, weighted
  /// 1/2 at the edge falling to 0 at W_e / 2 texels inside. All planes.
  void SampleBlended(int face, const Eigen::Vector2d& p_in_frame, int strip,
                     float* planes_out) const;
};

/// Per-edge values of one class of edges: their mean weighted by the points
/// measured on each edge, and the standard error of that mean (the edges'
/// spread over the square root of their count), so that classes of few edges
/// can be told apart from noise.
class EdgeTally {
 public:
  /// An edge whose `points` points summed `sum` (already per plane).
  void Add(double sum, int points);
  std::size_t Edges() const { return edges_; }
  double Mean() const;           ///< sum over points; 0 without points
  double StandardError() const;  ///< of Mean(); 0 below two edges

 private:
  std::size_t edges_ = 0, points_ = 0, measured_edges_ = 0;
  double sum_ = 0.0;
  // Running mean and summed squared deviations of the edges' own means (Welford).
  double edge_mean_ = 0.0, edge_squares_ = 0.0;
};

/// How well neighbouring patches agree across the mesh's shared edges, split
/// between edges whose faces lie in different regions of a distributed run and
/// the others: the mean squared difference of the blended coefficient planes
/// (orthonormal space, the neighbour's turned by the unfolding) between the two
/// faces' patches at points one texel apart along each edge. Two parts of
/// `elsewhere`: `next_to_borders`, between a face on a region border and a face of
/// its own region off it (both placed by rank 0 with the band, BordersPlacedFirst);
/// `next_to_band`, between a face of that band and a face of its own region off it
/// (the one placed by rank 0, the other by its region's rank: where the ranks' work
/// meets rank 0's).
struct EdgeMismatch {
  EdgeTally region_borders, next_to_borders, next_to_band, elsewhere;
};
EdgeMismatch MeasureEdgeMismatch(const MeshSynthesis& synthesis,
                                 const std::vector<int>& region_of_face);

/// Per-triangle image-constrained PTM synthesis on a mesh (paper 003 Algorithm 2).
/// `visibility` from sfm::ComputeVisibility for this mesh and reconstruction;
/// `photos` the usable photos (each image_id in the reconstruction). Throws
/// OptionError for bad options and InputError when the patches would not fit the
/// sample or would exceed max_texels (with the estimate).
/// `regions`: a distributed run (TriangleEngine::DistributeOver); on ranks other than
/// 0 the result is only this rank's share (rank_share_only). `sample_shadowing`: the
/// sample's self-shadowing (`--shadowed-synthesis`), with which placement, gains and
/// the photo-consistency pass (LRGB samples) relight the sample with the relief's
/// shadows (PtmSample).
MeshSynthesis SynthesizeMeshPtm(const mesh::TriangleMesh& mesh,
                                const sfm::Reconstruction& reconstruction,
                                const sfm::VisibilityResult& visibility,
                                const std::vector<MeshPhoto>& photos, const ptm::Ptm& sample,
                                const MeshSynthesisOptions& options,
                                const ProgressCallback& progress = {},
                                const FaceRegions* regions = nullptr,
                                const ptm::SelfShadowing* sample_shadowing = nullptr);

}  // namespace texlume::synth
