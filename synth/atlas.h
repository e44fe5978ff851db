#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "ptm/ptm.h"
#include "sfm/mesh.h"
#include "sfm/progress.h"
#include "synth/mesh_synthesis.h"

namespace texlume::synth {

/// How triangles are laid out in the atlases (paper 003 §3: per-triangle boxes).
enum class AtlasMode {
  kPerTriangle,  ///< each triangle's minimal bounding box, bin-packed (the paper)
  kCharts,       ///< connected triangles unfolded edge to edge into charts, packed
};

/// Settings of BuildAtlases.
struct AtlasOptions {
  AtlasMode mode = AtlasMode::kCharts;
  /// Width of every atlas and the most height (texels); the last atlas is cropped
  /// to the rows it uses. [64, 16384].
  int atlas_size = 2048;
  /// Texels of dilated values around every chart, so bilinear filtering (and
  /// one mipmap level) never reads texels of another chart. [1, 16].
  int gutter = 2;
  /// Blend width across mesh edges (W_e, texels; the synthesis strip). [2, 32].
  int blend_strip = 8;
  /// kCharts: a face joins a chart only while its normal is within this angle of
  /// the chart's first face (compact charts pack with less waste). (0, 180].
  double max_chart_normal_angle_deg = 180.0;
  /// kCharts: largest chart side in texels (0 = the atlas size); smaller charts
  /// nest better. [0, atlas_size].
  int max_chart_size = 192;
  void Check() const;
};

/// Where one face went: atlas pixel coordinates of a point p of its triangle
/// frame (world units) are x = offset.x + (R p).x / t, y = offset.y - (R p).y / t
/// (x right, y down, pixel centres at +0.5), R = rotation.
struct FacePlacement {
  int atlas = 0;
  int chart = 0;
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  /// The triangle's corners in atlas pixel coordinates.
  std::array<Eigen::Vector2d, 3> corners_px;
};

/// Packed, baked, blended PTM atlases and the texture coordinates into them.
/// Each atlas texel's coefficients are in the frame x = atlas +x (right), y =
/// atlas up (-rows), z = face normal, i.e. the tangent frame derived from the
/// texture coordinates (the convention of normal maps): a renderer takes
/// the light into the frame (dP/du, dP/dv, n) of each face, v up.
struct Atlases {
  std::vector<ptm::Ptm> ptms;
  std::vector<cv::Mat> coverage;  ///< CV_8UC1 per atlas: 255 inside a triangle, 128 gutter
  std::vector<FacePlacement> faces;
  int num_charts = 0;
  /// Texels whose centre lies inside a triangle / all atlas texels.
  double occupancy = 0.0;
  double seconds = 0.0;
};

/// Lays out the faces (per triangle or in charts), packs them into atlases
/// (per-triangle boxes: skyline, tallest first; charts: by their outlines at 16
/// rotations on a per-column skyline, largest first), and bakes every texel from the
/// synthesis, blended across mesh edges in the orthonormal space (paper 003
/// Fig. 4) and rotated into the atlas frame; gutters are dilated.
Atlases BuildAtlases(const sfm::TriangleMesh& mesh, const MeshSynthesis& synthesis,
                     const AtlasOptions& options, const ProgressCallback& progress = {});

/// Skyline bin packing of rectangles (w, h) into bins of `bin_width` x
/// `bin_height`, tallest first, each at the lowest, then leftmost, position.
/// Returns per rectangle (bin, x, y). Throws OptionError when one does not fit.
std::vector<std::array<int, 3>> PackSkyline(const std::vector<std::pair<int, int>>& sizes,
                                            int bin_width, int bin_height);

}  // namespace texlume::synth
