#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "btf/btf.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"
#include "synth/btf_sample.h"
#include "synth/triangle_engine.h"

namespace texlume::synth {

/// Settings of SynthesizeMeshBtf (paper 003 Algorithm 2 with a BTF sample,
/// paper 004's graph-cut seams): the engine's, and the BTF's seams and
/// photo-consistency pass.
struct BtfMeshSynthesisOptions : TriangleEngineOptions {
  /// Half-width of the band around each mesh edge in which the graph cut picks,
  /// texel by texel, one of the two faces' patches (texels). [1, strip].
  int seam_band = 4;
  /// Photo-consistency pass (beyond paper 004, as the PTM synthesis's):
  /// per-channel factors (ChannelFactorCorrection).
  bool photo_correction = true;
  /// lambda of that pass: photo noise as a share of the model's mean power;
  /// small trusts the photos, large keeps the sample. > 0.
  double correction_noise = 0.05;
  /// Smoothing of the factors (Gaussian sigma, photo pixels). > 0.
  double correction_sigma = 0.35;

  /// The engine's checks, then the seams' and the pass's.
  void Check() const;
};

/// Where a surface point takes its BTF from: a texel position in the sample and
/// the rotation from the frame the point was asked in to the sample's frame
/// (a tangent direction d becomes R(angle_rad) d in the sample frame).
struct BtfSampleLookup {
  int source_face = 0;                                  ///< the face whose patch supplies it
  Eigen::Vector2d sample_px = Eigen::Vector2d::Zero();  ///< x right, y down, centres at +0.5
  double angle_rad = 0.0;
  /// The photo-consistency factor per linear RGB channel (1 without one).
  Eigen::Vector3f colour_gain = Eigen::Vector3f::Ones();
};

/// The per-triangle BTF synthesis: each face's patch of the sample (the
/// engine's), and per face a label map from the graph cuts across its edges
/// (paper 004: seams instead of blending, which would mix mesostructure).
struct BtfMeshSynthesis : TriangleSynthesis {
  int sample_width = 0, sample_height = 0;
  /// Per face, CV_8UC1 over its patch rectangle (height x width, rows down):
  /// 0 = the face's own patch, 1 + k = the patch of the neighbour across edge k.
  std::vector<cv::Mat> labels;
  /// Per face, the photo-consistency factors (CV_32FC3, linear R, G, B) on a
  /// grid over its patch rectangle at `gain_density` cells per texel (x, y);
  /// empty: none (unseen faces, or the pass is off).
  std::vector<cv::Mat> colour_gain;
  std::vector<Eigen::Vector2d> gain_density;
  /// RMS linear difference to the constraint photos at their density (masked
  /// photo pixels of every constraint photo), before and after the factors.
  double photo_rms_quilted = 0, photo_rms_corrected = 0;
  std::size_t seam_edges = 0;           ///< mesh edges with a graph cut
  std::size_t seam_links = 0;           ///< texel pairs the seams cut
  double seam_cost = 0, edge_cost = 0;  ///< totals of the two below
  double seam_cost_per_link = 0;        ///< mean E_smooth term of a cut pair (geometry-map units)
  double edge_cost_per_link = 0;  ///< the same for a straight seam along the mesh edge (no cut)
  double seconds_seams = 0;
  /// Faces whose lookups another engine supplies in place of their patch (the
  /// graph-cut fill of the faces no photo sees, quilt/unseen_fill.h): per face
  /// whether it does (empty: none), and its sample position and the turn from
  /// the face frame into the sample's at a point of the face frame (false where
  /// it has none, and the patch is read). Factors of 1.
  std::vector<bool> filled;
  std::function<bool(int face, const Eigen::Vector2d& p_in_frame, Eigen::Vector2d* sample_px,
                     double* face_to_sample_rad)>
      fill;

  /// The sample texel a point of face `face` (its triangle frame, world units)
  /// shows: a filled face's fill; else its patch, or across a seam the
  /// neighbour's (that neighbour's fill when it is filled).
  BtfSampleLookup Lookup(int face, const Eigen::Vector2d& p_in_frame) const;
};

/// Per-triangle image-constrained BTF quilting: the TriangleEngine with a
/// BtfSample (each photo relit with its own view direction and lights in the
/// triangle frame, f = sum_i g_i p_i(v, l), compared in the linear domain),
/// ChannelFactorCorrection, then CutSeams over the geometry maps in a band of
/// seam_band texels on both sides of every shared edge.
/// Throws OptionError for bad options and InputError when a patch does not fit
/// the sample or the patches exceed max_texels.
/// `regions`: a distributed run (TriangleEngine::DistributeOver); on ranks other than
/// 0 the result is only this rank's share (rank_share_only).
BtfMeshSynthesis SynthesizeMeshBtf(
    const mesh::TriangleMesh& mesh, const sfm::Reconstruction& reconstruction,
    const sfm::VisibilityResult& visibility, const std::vector<MeshPhoto>& photos,
    const btf::BtfFactorisation& sample, const BtfMeshSynthesisOptions& options,
    const ProgressCallback& progress = {}, const FaceRegions* regions = nullptr);

}  // namespace texlume::synth
