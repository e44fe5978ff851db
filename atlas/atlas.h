#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "core/progress.h"
#include "mesh/mesh.h"
#include "ptm/ptm.h"
#include "synth/mesh_synthesis.h"

namespace texlume::atlas {

/// How triangles are laid out in the atlases (paper 003 §3: per-triangle boxes).
enum class AtlasMode {
  kPerTriangle,  ///< each triangle's minimal bounding box, bin-packed (the paper)
  kCharts,       ///< connected triangles flattened into charts (rigid or conformal), packed
};

/// How kCharts flattens a chart (synth/charts.h).
enum class ChartFlattening {
  kRigid,      ///< faces unfolded edge to edge: no distortion, cracks around vertices
  kConformal,  ///< least-squares conformal map: no cracks, texel stretch within a bound
  kStrips,     ///< triangle strips mapped onto straight bands that tile atlas rows
  kAuto,       ///< strips and rigid charts both laid out; the one with fewer atlas texels
};

/// Settings of BuildAtlases.
struct AtlasOptions {
  AtlasMode mode = AtlasMode::kCharts;
  ChartFlattening flattening = ChartFlattening::kAuto;
  /// Width of every atlas and the most height (texels); the last atlas is cropped
  /// to the rows it uses. [64, 16384].
  int atlas_size = 2048;
  /// Texels of dilated values around every chart, so the renderer's and the
  /// viewer's Catmull-Rom reads (2 texels past a chart's last centre) never read
  /// texels of another chart. [2, 16].
  int gutter = 2;
  /// Blend width across mesh edges (W_e, texels; the synthesis strip). [2, 32].
  int blend_strip = 8;
  /// kCharts: a face joins a chart only while its normal is within this angle of
  /// the chart's seed face. (0, 180].
  double max_chart_normal_angle_deg = 180.0;
  /// kCharts: largest chart side in texels (0 = the atlas size); kConformal
  /// grows charts around their seed face within a square of this side on the
  /// seed's tangent plane. Smaller charts nest better. kStrips ignores it
  /// (bands run as long as a row). [0, atlas_size].
  int max_chart_size = 192;
  /// kConformal, kStrips: most texel stretch of a face in a chart (the singular values of
  /// the chart map, texels per texel of the synthesis, stay in [1/s, s]); a
  /// chart beyond it is split. [1.01, 4].
  double max_chart_stretch = 1.25;
  void Check() const;
};

/// Where one face went: atlas pixel coordinates of a point p of its triangle
/// frame (world units) are x = offset.x + (L p).x / t, y = offset.y - (L p).y / t
/// (x right, y down, pixel centres at +0.5), L = linear: a rotation for a rigid
/// placement, near a rotation (conformal, texel stretch near 1) in a chart.
struct FacePlacement {
  int atlas = 0;
  int chart = 0;
  Eigen::Matrix2d linear = Eigen::Matrix2d::Identity();
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  /// The triangle's corners in atlas pixel coordinates.
  std::array<Eigen::Vector2d, 3> corners_px;

  /// The point of the triangle frame (world units) at atlas pixel coordinates `px`.
  Eigen::Vector2d FrameFromAtlas(const Eigen::Vector2d& px, double texel_size) const;
  /// The angle (radians) of the atlas +x direction (dP/du) in the triangle
  /// frame: the atlas frame is the triangle frame turned by it (about the normal).
  double AtlasFrameAngle() const;
};

/// Texel stretch of a layout: per face the singular values of its map from
/// the triangle frame to the atlas, in texels per texel of the synthesis (1:
/// the synthesis density; below 1 the atlas holds less detail than synthesised).
struct AtlasStretch {
  double mean = 1.0;  ///< area-weighted mean of sqrt(s1 s2) (the density's scale)
  double min = 1.0;   ///< smallest singular value over the faces
  double max = 1.0;   ///< largest singular value over the faces
};
/// Where every face goes, without values: placements and atlas sizes.
struct AtlasLayout {
  std::vector<FacePlacement> faces;
  std::vector<cv::Size> atlas_sizes;  ///< texels; the last atlas cropped to the rows it uses
  int num_charts = 0;
  /// kCharts: the flattening the charts have (never kAuto: the one it chose).
  ChartFlattening flattening = ChartFlattening::kRigid;
  /// Texels of all atlases (the last one cropped).
  std::int64_t Texels() const;
};

/// Lays out the faces (per triangle or in conformal charts, synth/charts.h) and
/// packs them into atlases (per-triangle boxes: skyline, tallest first; charts:
/// by their outlines at 16 rotations, bottom-left, largest first). `patches` give each face's
/// frame and corners, `unfoldings` its neighbours across edges; `texel_size` in
/// world units. Throws OptionError when a chart does not fit an atlas.
AtlasLayout LayoutAtlases(const mesh::TriangleMesh& mesh,
                          const std::vector<synth::TrianglePatch>& patches,
                          const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
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

/// What a sample kind writes at one surface point: `face` and the point in its
/// triangle frame (world units) in, the atlas texel's planes out (`out` holds
/// the baker's plane count).
using TexelLookup = std::function<void(int face, const Eigen::Vector2d& p_in_frame, float* out)>;

/// Atlas planes baked from per-surface-point lookups, with the texels they cover.
struct BakedPlanes {
  std::vector<std::vector<cv::Mat>> planes;  ///< per atlas, `num_planes` CV_32FC1
  std::vector<cv::Mat> coverage;             ///< as AtlasCoverage
  double occupancy = 0.0;                    ///< texels inside triangles over all atlas texels
};

/// The one baker of every sample kind: per atlas texel inside a face or its
/// gutter, the lookup's `num_planes` values (VisitAtlasTexels), then the gutters
/// dilated (DilateGutters). PTM atlases (BuildAtlases), BTF atlases
/// (BuildBtfAtlases) and colour samples (as their Lambertian PTM) differ only in
/// the lookup.
BakedPlanes BakeAtlasPlanes(const AtlasLayout& layout, double texel_size, int gutter,
                            int num_planes, const TexelLookup& lookup,
                            const ProgressCallback& progress = {});

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
  ChartFlattening flattening = ChartFlattening::kRigid;  ///< as AtlasLayout::flattening
  /// Texels whose centre lies inside a triangle / all atlas texels.
  double occupancy = 0.0;
  double seconds = 0.0;
  AtlasStretch stretch;  ///< of the faces' maps (1 for rigid placements)
};

AtlasStretch MeasureStretch(const std::vector<synth::TrianglePatch>& patches,
                            const AtlasLayout& layout);

/// "rigid", "conformal", "strips" or "auto" (the manifest's and the CLI's names).
const char* ChartFlatteningName(ChartFlattening flattening);

/// Lays out the faces (per triangle or in charts), packs them into atlases
/// (per-triangle boxes: skyline, tallest first; charts: by their outlines at 16
/// rotations on a per-column skyline, largest first), and bakes every texel from the
/// synthesis, blended across mesh edges in the orthonormal space (paper 003
/// Fig. 4) and rotated into the atlas frame; gutters are dilated.
Atlases BuildAtlases(const mesh::TriangleMesh& mesh, const synth::MeshSynthesis& synthesis,
                     const AtlasOptions& options, const ProgressCallback& progress = {});

/// Skyline bin packing of rectangles (w, h) into bins of `bin_width` x
/// `bin_height`, tallest first, each at the lowest, then leftmost, position.
/// Returns per rectangle (bin, x, y). Throws OptionError when one does not fit.
std::vector<std::array<int, 3>> PackSkyline(const std::vector<std::pair<int, int>>& sizes,
                                            int bin_width, int bin_height);

}  // namespace texlume::atlas
