#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "sfm/mesh.h"
#include "synth/mesh_synthesis.h"

namespace texlume::synth {

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
  double texel_size = 1.0;           ///< world units
  double max_extent_texels = 188.0;  ///< largest chart side
  double max_normal_angle_deg = 180.0;
  int gutter = 2;  ///< texels; faces that do not share a vertex keep 2 gutters + 1 apart
};

/// Charts unfolded edge to edge without distortion: from seeds in breadth-first
/// order, each neighbour is unfolded across the shared edge (a rotation and a
/// translation) and joins when it overlaps nothing, keeps clear of the chart's
/// faces it does not touch on the mesh, and the chart stays within the extent.
std::vector<std::vector<ChartFace>> MakeRigidCharts(
    const sfm::TriangleMesh& mesh, const std::vector<TrianglePatch>& patches,
    const std::vector<std::array<Unfolding, 3>>& unfoldings, const RigidChartOptions& options);

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
    const sfm::TriangleMesh& mesh, const std::vector<TrianglePatch>& patches,
    const std::vector<std::array<Unfolding, 3>>& unfoldings, const ConformalChartOptions& options,
    ConformalChartStats* stats = nullptr);

/// Singular values (largest first) of a 2x2 map.
Eigen::Vector2d SingularValues2(const Eigen::Matrix2d& m);

}  // namespace texlume::synth
