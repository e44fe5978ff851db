#pragma once

#include <Eigen/Core>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "atlas/atlas.h"
#include "btf/btf.h"
#include "core/progress.h"
#include "mesh/mesh.h"
#include "ptm/ptm.h"
#include "synth/mesh_btf.h"

namespace texlume::atlas {

/// The BTF synthesis laid out in atlases (atlas::LayoutAtlases, the same charts
/// and packing as PTM models). Per atlas texel, paper 004's representation: the
/// position in the sample it shows and the rotation to the sample's frame; the
/// geometry maps there are baked for export and rendering.
struct BtfAtlases {
  AtlasLayout layout;
  std::vector<cv::Mat> coverage;  ///< CV_8UC1 per atlas: 255 inside, 128 gutter, 64 dilated
  /// CV_32FC3 per atlas: sample x, sample y (texels, x right, y down, centres at
  /// +0.5), angle (radians): a tangent direction d in the atlas frame (x = atlas
  /// right, y = atlas up, z = normal) is R(angle) d in the sample's frame.
  std::vector<cv::Mat> sample_coords;
  /// CV_32FC3 per atlas: the photo-consistency factors (linear R, G, B) the
  /// BTF is multiplied by at each texel (synth::BtfMeshSynthesis::colour_gain).
  std::vector<cv::Mat> colour_gain;
  /// Per atlas, n CV_32FC1 planes: g_i at each texel's sample position.
  std::vector<std::vector<cv::Mat>> geometry;
  double occupancy = 0.0;
};

/// What one surface point of a BTF model shows (BtfAtlases' channels).
struct BtfAtlasLookup {
  Eigen::Vector2d sample_px = Eigen::Vector2d::Zero();  ///< x right, y down, centres at +0.5
  /// A tangent direction d in the atlas frame is R(angle) d in the sample's frame.
  double atlas_to_sample_rad = 0.0;
  Eigen::Vector3f colour_gain = Eigen::Vector3f::Ones();
};
using BtfTexelLookup = std::function<BtfAtlasLookup(int face, const Eigen::Vector2d& p_in_frame)>;

/// Bakes the atlases of `layout` (BakeAtlasPlanes) from per-surface-point
/// lookups: the sample coordinates, the factors and the geometry maps there.
/// Every engine's BTF model goes through it.
BtfAtlases BakeBtfAtlases(AtlasLayout layout, double texel_size, int gutter,
                          const btf::BtfFactorisation& sample, const BtfTexelLookup& lookup,
                          const ProgressCallback& progress = {});

/// Lays out and bakes the atlases of the per-triangle engine (BakeBtfAtlases).
/// The graph-cut labels decide which patch a texel shows; nothing is blended.
BtfAtlases BuildBtfAtlases(const mesh::TriangleMesh& mesh, const synth::BtfMeshSynthesis& synthesis,
                           const btf::BtfFactorisation& sample, const AtlasOptions& options,
                           const ProgressCallback& progress = {});

/// A PTM preview of BTF atlases for PTM viewers and exports (the web viewer,
/// glTF extras, .ptm): per texel an RGB PTM in the display domain, in the atlas
/// frame, fitted by least squares to the BTF seen head-on (v = normal) under 25
/// lights between 15 and 90 degrees of elevation, with the photo-consistency
/// factors. View dependence is lost.
std::vector<ptm::Ptm> PreviewPtms(const BtfAtlases& atlases, const btf::BtfFactorisation& sample,
                                  const ProgressCallback& progress = {});

}  // namespace texlume::atlas
