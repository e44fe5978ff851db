#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "btf/btf.h"
#include "sfm/mesh.h"
#include "sfm/progress.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"
#include "synth/mesh_synthesis.h"

namespace texlume::btf {

/// Settings of SynthesizeMeshBtf (paper 003 Algorithm 2 with a BTF sample,
/// paper 004's graph-cut seams).
struct BtfMeshSynthesisOptions {
  /// World units per texel of the BTF sample. > 0.
  double sample_texel_size = 0.0;
  /// W_e: texels of strip around each triangle's bounding box; the overlap
  /// constraint compares the texels within W_e of a synthesised neighbour. [2, 32].
  int strip = 8;
  /// Half-width of the band around each mesh edge in which the graph cut picks,
  /// texel by texel, one of the two faces' patches (texels). [1, strip].
  int seam_band = 4;
  /// Candidates kept by the image score before the overlap constraint. >= 1.
  int top_k = 12;
  /// Most photos constraining one triangle (the best view, then the most
  /// frontal fully visible ones). >= 1.
  int max_views = 4;
  /// As synth::MeshSynthesisOptions::tangent_frame.
  synth::TangentFrame tangent_frame = synth::TangentFrame::kAuto;
  Eigen::Vector3d field_direction_in_world = Eigen::Vector3d::UnitZ();
  /// Triangles seen in no photo: pick at random among placements whose overlap
  /// error is within (1 + tolerance) of the best. >= 0.
  double tolerance = 0.1;
  /// Fewest rectified photo pixels inside a triangle for the photo to constrain it. >= 1.
  int min_photo_pixels = 6;
  /// Photo-consistency pass (beyond paper 004, as the PTM synthesis's): per
  /// triangle seen in photos, a per-channel factor k on a grid at the best
  /// photo's density, the most probable under a prior k = 1 given every
  /// constraint photo, k = (sum_r m_r p_r + lambda mu) / (sum_r m_r^2 + lambda mu)
  /// with m_r the chosen patch relit under photo r (times its gain), p_r the
  /// photo, mu the mean m^2: the photos' low frequencies (stains, colour, the
  /// exact light and dark spots) on the sample's fine detail.
  bool photo_correction = true;
  /// lambda above: photo noise as a share of the model's mean power; small
  /// trusts the photos, large keeps the sample. > 0.
  double correction_noise = 0.05;
  /// Smoothing of the factors (Gaussian sigma, photo pixels; normalised over the
  /// observed cells, which also carries them into the strip, with 4 sigma where
  /// no observed cell is near). > 0.
  double correction_sigma = 0.35;
  /// Refuse up front when the patches would take more texels than this.
  std::int64_t max_texels = std::int64_t{1} << 30;
  std::uint32_t seed = 1;

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

/// The per-triangle BTF synthesis: each face's patch of the sample (rectangle
/// as synth::TrianglePatch), and per face a label map from the graph cuts
/// across its edges (paper 004: seams instead of blending, which would mix
/// mesostructure).
struct BtfMeshSynthesis {
  double texel_size = 0.0;  ///< world units
  int sample_width = 0, sample_height = 0;
  std::vector<synth::TrianglePatch> patches;
  std::vector<std::array<synth::Unfolding, 3>> unfoldings;
  /// Per face, CV_8UC1 over its patch rectangle (height x width, rows down):
  /// 0 = the face's own patch, 1 + k = the patch of the neighbour across edge k.
  std::vector<cv::Mat> labels;
  std::vector<double> photo_gains;  ///< per photo (linear exposure x intensity)
  /// Per face, the photo-consistency factors (CV_32FC3, linear R, G, B) on a
  /// grid over its patch rectangle at `gain_density` cells per texel (x, y);
  /// empty: none (unseen faces, or the pass is off).
  std::vector<cv::Mat> colour_gain;
  std::vector<Eigen::Vector2d> gain_density;
  /// RMS linear difference to the constraint photos at their density (masked
  /// photo pixels of every constraint photo), before and after the factors.
  double photo_rms_quilted = 0, photo_rms_corrected = 0;
  std::size_t num_from_photos = 0, num_from_neighbours = 0, num_random = 0;
  std::size_t seam_edges = 0;           ///< mesh edges with a graph cut
  std::size_t seam_links = 0;           ///< texel pairs the seams cut
  double seam_cost = 0, edge_cost = 0;  ///< totals of the two below
  double seam_cost_per_link = 0;        ///< mean E_smooth term of a cut pair (geometry-map units)
  double edge_cost_per_link = 0;  ///< the same for a straight seam along the mesh edge (no cut)
  double seconds_synthesis = 0, seconds_seams = 0;
  /// The frames the patches have (kAuto resolved), and the sample's coherence
  /// that kAuto judged by (-1: not measured); see synth::MeshSynthesis.
  synth::TangentFrame tangent_frame = synth::TangentFrame::kFirstEdge;
  double sample_coherence = -1.0;

  /// The sample texel a point of face `face` (its triangle frame, world units) shows.
  BtfSampleLookup Lookup(int face, const Eigen::Vector2d& p_in_frame) const;
};

/// Per-triangle image-constrained BTF quilting. Like synth::SynthesizeMeshPtm,
/// faces are visited breadth first; a face seen fully in photos ranks every
/// placement of its patch in the sample by eq. 3 of paper 003 summed over up to
/// max_views photos, each relit with its own view direction and lights in the
/// triangle frame (f = sum_i g_i p_i(v, l), compared in the linear domain at the
/// photo's density after a gain per photo), then keeps, of the top_k, the one
/// closest to the synthesised neighbours in the geometry-map space
/// (g_0..g_{n-1}); unseen faces take the overlap constraint alone (FFT) or a
/// random placement. Then every shared edge gets a graph cut (paper 004
/// eq. E_smooth, V(p, q) = |f_A(p) - f_B(p)| + |f_A(q) - f_B(q)| over the
/// geometry maps) in a band of seam_band texels on both sides.
/// Throws OptionError for bad options and InputError when a patch does not fit
/// the sample or the patches exceed max_texels.
BtfMeshSynthesis SynthesizeMeshBtf(const sfm::TriangleMesh& mesh,
                                   const sfm::Reconstruction& reconstruction,
                                   const sfm::VisibilityResult& visibility,
                                   const std::vector<synth::MeshPhoto>& photos,
                                   const BtfFactorisation& sample,
                                   const BtfMeshSynthesisOptions& options,
                                   const ProgressCallback& progress = {});

/// The geometry-map vector (n values) of the sample at a continuous texel
/// position (x right, y down, centres at +0.5), bilinear, clamped to the sample.
void SampleGeometry(const BtfFactorisation& sample, const Eigen::Vector2d& sample_px, float* out);

}  // namespace texlume::btf
