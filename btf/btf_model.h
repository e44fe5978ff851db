#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "btf/btf.h"
#include "core/progress.h"
#include "ptm/ptm.h"
#include "synth/atlas.h"
#include "synth/mesh_btf.h"
#include "synth/model_render.h"
#include "synth/pipeline.h"

namespace texlume::btf {

/// The BTF synthesis laid out in atlases (synth::LayoutAtlases, the same charts
/// and packing as PTM models). Per atlas texel, paper 004's representation: the
/// position in the sample it shows and the rotation to the sample's frame; the
/// geometry maps there are baked for export and rendering.
struct BtfAtlases {
  synth::AtlasLayout layout;
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

/// Lays out and bakes the atlases. The graph-cut labels decide which patch a
/// texel shows; nothing is blended.
BtfAtlases BuildBtfAtlases(const sfm::TriangleMesh& mesh, const synth::BtfMeshSynthesis& synthesis,
                           const BtfFactorisation& sample, const synth::AtlasOptions& options,
                           const ProgressCallback& progress = {});

/// A PTM preview of BTF atlases for PTM viewers and exports (the web viewer,
/// glTF extras, .ptm): per texel an RGB PTM in the display domain, in the atlas
/// frame, fitted by least squares to the BTF seen head-on (v = normal) under 25
/// lights between 15 and 90 degrees of elevation, with the photo-consistency
/// factors. View dependence is lost.
std::vector<ptm::Ptm> PreviewPtms(const BtfAtlases& atlases, const BtfFactorisation& sample,
                                  const ProgressCallback& progress = {});

/// The BTF parts of a model folder written by RunBtfSynthJob.
struct BtfModel {
  BtfFactorisation sample;
  std::vector<cv::Mat> sample_coords;  ///< as BtfAtlases
  std::vector<cv::Mat> colour_gain;    ///< as BtfAtlases (all 1 when the file has none)
};

/// Reads `btf/` (the factorisation) and `btf_atlas_K.exr` (sample coordinates
/// and photo-consistency factors) of a model folder.
/// Throws InputError naming the file when one is missing, malformed, or its
/// size differs from the model's atlas.
BtfModel ReadBtfModel(const std::filesystem::path& dir, const synth::TexturedModel& model);

/// The BTF model's display RGB at one ray hit: the nearest atlas texel's sample
/// position moved by the hit's offset from it, view and light directions in the
/// atlas frame (the renderer's smooth frame) turned into the sample frame by the
/// texel's angle, f = sum_lights I sum_i g_i(x) p_i(v, l) (g bilinear in the
/// sample; p interpolated over the direction grid), times the texel's
/// photo-consistency factors, then sRGB.
Eigen::Vector3f ShadeBtf(const BtfModel& model, const synth::ModelRenderer::SurfaceSample& sample,
                         const std::vector<sfm::ObjectLight>& lights);

/// Inputs and settings of `texlume synth --btf DIR`.
struct BtfSynthJobOptions {
  /// Paths, atlas, visibility, subdivision and report settings; `sample_file`
  /// is ignored and `synthesis.sample_texel_size` unused.
  synth::SynthJobOptions job;
  /// A BTF capture folder (btf.json) or a factorisation (btf_svd.json).
  std::filesystem::path btf;
  /// Components kept when factorising a capture (paper 004: 40).
  int components = 40;
  /// sample_texel_size 0 = the capture's texel size.
  synth::BtfMeshSynthesisOptions synthesis;

  /// Throws OptionError when a path is missing or a setting is out of range
  /// (the synthesis settings with the texel size still to be resolved).
  void Check() const;
};

struct BtfSynthJobSummary : synth::SynthCounts {
  std::size_t seam_edges = 0;
  double seam_cost_per_link = 0, edge_cost_per_link = 0;
  double seconds_factorise = 0, seconds_synthesis = 0, seconds_seams = 0, seconds_atlas = 0,
         seconds_preview = 0, seconds_export = 0, seconds_total = 0;
};

/// The main job with a BTF sample: reads the inputs (synth::LoadSynthInputs),
/// factorises the capture, synthesises (synth::SynthesizeMeshBtf), lays out and bakes
/// the atlases, and writes a model folder: everything a PTM model folder holds
/// (the PTM preview as its atlases, the baselines `texlume render` draws), plus
/// `btf/` (the factorisation: geometry_maps.exr, appearance.bin, btf_svd.json),
/// `btf_atlas_K.exr` (per texel its sample position and angle) and the baked
/// geometry-map atlases `btf_geometry_K_P.png` (docs/btf.md). Nothing is
/// written on error.
BtfSynthJobSummary RunBtfSynthJob(const BtfSynthJobOptions& options,
                                  const ProgressCallback& progress = {});

}  // namespace texlume::btf
