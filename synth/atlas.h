#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
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

/// Where every face goes, without values: placements and atlas sizes.
struct AtlasLayout {
  std::vector<FacePlacement> faces;
  std::vector<cv::Size> atlas_sizes;  ///< texels; the last atlas cropped to the rows it uses
  int num_charts = 0;
};

/// Lays out the faces (per triangle or in charts) and packs them into atlases
/// (per-triangle boxes: skyline, tallest first; charts: by their outlines at 16
/// rotations on a per-column skyline, largest first). `patches` give each face's
/// frame and corners, `unfoldings` its neighbours across edges; `texel_size` in
/// world units. Throws OptionError when a chart does not fit an atlas.
AtlasLayout LayoutAtlases(const sfm::TriangleMesh& mesh, const std::vector<TrianglePatch>& patches,
                          const std::vector<std::array<Unfolding, 3>>& unfoldings,
                          double texel_size, const AtlasOptions& options,
                          const ProgressCallback& progress = {});

/// Called for an atlas texel (x, y) of `atlas` that face `face` fills;
/// `p_in_frame` is the texel centre in the face's triangle frame (world units).
using AtlasTexelVisitor =
    std::function<void(int atlas, int x, int y, int face, const Eigen::Vector2d& p_in_frame)>;

/// Texels a layout fills, per atlas (CV_8UC1: 255 inside a triangle, 128
/// gutter, 64 dilated), and the count inside triangles.
struct AtlasCoverage {
  std::vector<cv::Mat> coverage;
  std::size_t inside_texels = 0;
};

/// Visits every texel inside a face (once; the first face wins on a shared edge)
/// and every texel within `gutter` texels of one (possibly again, by a nearer face).
AtlasCoverage VisitAtlasTexels(const AtlasLayout& layout, double texel_size, int gutter,
                               const AtlasTexelVisitor& visit,
                               const ProgressCallback& progress = {});

/// Fills texels that `coverage` marks 0 next to filled ones with the mean of
/// their filled 8-neighbours, `rings` times (marking them 64), in every plane.
void DilateGutters(std::vector<cv::Mat>& planes, cv::Mat& coverage, int rings);

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
