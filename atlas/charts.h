#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

#include "mesh/mesh.h"
#include "synth/mesh_synthesis.h"

namespace texlume::atlas {

/// A face's place in a chart plane: chart = linear * p + translation, p in the
/// face's triangle frame, both in world units. `linear` is a rotation for a
/// rigid placement and close to one (conformal, scale near 1) in a conformal chart.
struct ChartFace {
  int face = -1;
  Eigen::Matrix2d linear = Eigen::Matrix2d::Identity();
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
};

/// Settings of MakeRigidCharts.
struct RigidChartOptions {
  double texel_size = 1.0;              ///< world units, > 0
  double max_extent_texels = 188.0;     ///< largest chart side, >= 1
  double max_normal_angle_deg = 180.0;  ///< (0, 180]
  int gutter = 2;  ///< texels, >= 0; faces that do not share a vertex keep 2 gutters + 1 apart

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// Charts unfolded edge to edge without distortion: from seeds in breadth-first
/// order, each neighbour is unfolded across the shared edge (a rotation and a
/// translation) and joins when it overlaps nothing, keeps clear of the chart's
/// faces it does not touch on the mesh, and the chart stays within the extent.
std::vector<std::vector<ChartFace>> MakeRigidCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    const RigidChartOptions& options);

/// Settings of MakeConformalCharts.
struct ConformalChartOptions {
  double texel_size = 1.0;  ///< world units
  /// A chart grows around its seed face while its faces' centroids stay within
  /// this square (side in texels, on the seed's tangent plane). > 0.
  double max_side_texels = 512.0;
  /// A face joins only while its normal is within this angle of the seed's. (0, 180].
  double max_normal_angle_deg = 180.0;
  /// Every face's texel stretch (singular values of the chart map, once the
  /// chart's area equals the surface's) must be in [1 / s, s]; else the chart is
  /// split. > 1.
  double max_stretch = 1.25;
  /// Largest chart side in texels (an atlas less its gutters); larger charts are split.
  double max_extent_texels = 2044.0;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// What MakeConformalCharts did.
struct ConformalChartStats {
  int grown = 0;  ///< charts grown before splitting
  int splits = 0;
};

/// Charts of connected faces with least-squares conformal maps (LSCM, Lévy et
/// al. 2002): faces are grown into square-ish charts of nearly the same normal,
/// each chart is flattened by the conformal map with two pinned vertices and
/// scaled so its area equals the surface's, and a chart with a flipped or
/// overlapping face, a face stretched beyond `max_stretch`, or a side beyond
/// `max_extent_texels` is split in two across its longer side and redone. Every
/// face ends in exactly one chart (a lone face is placed rigidly).
std::vector<std::vector<ChartFace>> MakeConformalCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    const ConformalChartOptions& options, ConformalChartStats* stats = nullptr);

/// The least-squares conformal map (LSCM, Lévy et al. 2002, eq. 3) of a
/// connected set of faces, in texels of `texel_size` world units (y up): per
/// face, its corners' chart coordinates. `corners_texels(f)`: face f's corners
/// in its triangle frame, texels (chart_parts::FrameCornersTexels). Two
/// vertices far apart are pinned at their distance in the world, so the map's
/// scale is near 1. False when the system is singular.
bool LeastSquaresConformalMap(
    const mesh::TriangleMesh& mesh,
    const std::function<std::array<Eigen::Vector2d, 3>(int face)>& corners_texels,
    const std::vector<int>& faces, double texel_size,
    std::vector<std::array<Eigen::Vector2d, 3>>* corners_uv);

/// Which edge of a strip's seed face lies on the band line (after preferring
/// one along the charted region or the mesh border).
enum class StripSide {
  kTallest,           ///< the one the face is tallest over (its shortest edge)
  kNearestPreferred,  ///< the one whose height is nearest the preferred band height
};

/// Settings of MakeStripCharts.
struct StripChartOptions {
  double texel_size = 1.0;  ///< world units
  /// Every face's texel stretch (singular values of its map into the band) stays
  /// in [1 / s, s]; a strip ends before a face that would exceed it. > 1.
  double max_stretch = 1.25;
  /// Longest band in texels (an atlas less its gutters). > 0.
  double max_length_texels = 2044.0;
  /// A face joins only while its normal is within this angle of the seed's. (0, 180].
  double max_normal_angle_deg = 180.0;
  StripSide side = StripSide::kTallest;
  /// Faces around a vertex of at least this many faces are charted first, as a
  /// fan cut into sectors (0: no fans). 0 or >= 3.
  int min_fan_faces = 8;
  /// Bands are stacked on each other (sharing a line, so no gutter rows between
  /// them) up to this height in texels; 0: no stacking. >= 0.
  double max_stack_texels = 0.0;
  /// A stacked band must span at least this fraction of the band below. (0, 1].
  double min_stack_cover = 0.75;
  /// A stacked band reaches at most this far (texels) beyond either end of the
  /// chain of the band below it; < 0: no limit.
  double max_stack_overhang_texels = -1.0;
  /// Atlas gutter in texels (>= 0): fan sectors are sized for it.
  int gutter = 2;
  /// For irregular meshes: a band whose seed is not near the preferred height
  /// takes the nearest height of the ladder preferred * max_stretch^k (so the
  /// bands share few heights and fill atlas rows), and an unstacked band's face
  /// that the rung's similarity would stretch beyond the bound takes its apex
  /// at the least-stretching place on either line instead of ending the band.
  bool fit_irregular_faces = false;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// What MakeStripCharts did.
struct StripChartStats {
  int strips = 0;
  int lone_faces = 0;   ///< seeds that fit no band (placed rigidly on their own)
  int fans = 0;         ///< runs of faces around a vertex charted as fans
  int stacked = 0;      ///< bands stacked on others (in their charts)
  int fan_sectors = 0;  ///< their sectors: one chart each, the first charts returned
};

/// Charts that tile: triangle strips mapped onto straight bands. From seeds
/// with the fewest free neighbours (then in breadth-first order), a strip
/// starts with a face whose side edge lies on the band's bottom line and whose
/// apex sets the band's height (whole texels; the preferred height, the median
/// of the faces' tallest heights, when it is near); it
/// grows both ways across its rungs (the edges that cross the band): the next
/// face's apex is placed by the similarity that maps the rung onto its place
/// in the band and goes to the nearer band line, so every face has one edge on
/// a line and its apex on the other (a piecewise-affine map, continuous
/// across rungs). A strip ends at a used face, at a face whose stretch would
/// leave [1/s, s], or at `max_length_texels`. Its ends are then squared (the end
/// rung made to cross straight) where the stretch bound allows. Bands are
/// rectangles but for slanted ends, so they pack into atlas rows with only their gutters
/// between them. The band lines lie on texel centres (at 0.5 + whole texels, less
/// a hair), so a band of height H texels fills H + 1 rows and the gutter rings
/// beyond it are whole rows. Before any strip, fans (the faces around a vertex
/// of at least `min_fan_faces` faces, such as cylinder caps, which no band can
/// follow) are unfolded rigidly about their centre and cut into sectors of at
/// most 90 degrees standing upright on the centre, so that sectors turned by
/// 180 degrees nest between upright ones in an atlas row; a flat fan's sectors
/// take in the faces of its plane beyond it (a subdivided cap's rings). With
/// `max_stack_texels`, a band is grown on the top line of the last one, its
/// vertices on that line kept where the band below put them, so stacked bands
/// form one chart with no gutter rows between them (a grid on developable
/// surfaces such as a cylinder's side); a stacked band's vertex on its free
/// line is placed from the next face's edge on the band below, so the
/// difference of the two lines' lengths on a curved surface does not add up
/// along the band; with `max_stack_overhang_texels`, a
/// stacked band stays near the ends of the band below (stacks stay near
/// rectangles on curved surfaces). Every face ends in exactly one chart.
std::vector<std::vector<ChartFace>> MakeStripCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    const StripChartOptions& options, StripChartStats* stats = nullptr);

/// The band height strips prefer (texels): the median over the faces of each
/// face's tallest height, rounded, so bands of near-equal faces share one height.
double PreferredBandHeight(const std::vector<synth::TrianglePatch>& patches, double texel_size);

/// Singular values (largest first) of a 2x2 map.
Eigen::Vector2d SingularValues2(const Eigen::Matrix2d& m);

}  // namespace texlume::atlas
