#pragma once

#include <Eigen/Core>
#include <array>
#include <utility>

#include "mesh/mesh.h"

namespace texlume::mesh {

/// The local frame of a triangle (paper 003 §3.0.2): origin at the centroid,
/// X along v0->v1 (or a given tangent), Z the face normal, Y = Z x X. All axes are
/// unit vectors in the world frame.
struct TriangleFrame {
  Eigen::Vector3d origin_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d z_axis = Eigen::Vector3d::UnitZ();

  /// A world-frame direction expressed in this frame.
  Eigen::Vector3d DirectionInFrame(const Eigen::Vector3d& direction_in_world) const {
    return {x_axis.dot(direction_in_world), y_axis.dot(direction_in_world),
            z_axis.dot(direction_in_world)};
  }
  /// A world point expressed in this frame.
  Eigen::Vector3d PointInFrame(const Eigen::Vector3d& point_in_world) const {
    return DirectionInFrame(point_in_world - origin_in_world);
  }
};

/// The frame of face `face` with X along v0->v1. Precondition: non-degenerate face.
TriangleFrame MakeTriangleFrame(const mesh::TriangleMesh& mesh, std::size_t face);

/// The frame of face `face` with X along `tangent_in_world` projected onto the
/// face plane (for a smooth tangent field). Falls back to v0->v1 when the tangent
/// is (nearly) parallel to the normal.
TriangleFrame MakeTriangleFrame(const mesh::TriangleMesh& mesh, std::size_t face,
                                const Eigen::Vector3d& tangent_in_world);

/// Distance from p to the segment [a, b] (2D).
double DistanceToSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                         const Eigen::Vector2d& p);

/// Signed distance from p to a 2D triangle (either winding): minus the distance
/// to the nearest edge inside (edges included), the distance outside.
double SignedDistanceToTriangle(const std::array<Eigen::Vector2d, 3>& corners,
                                const Eigen::Vector2d& p);

/// Whether SignedDistanceToTriangle(corners, p) <= reach, for reach >= 0: true
/// inside without measuring the distance.
bool WithinReachOfTriangle(const std::array<Eigen::Vector2d, 3>& corners, const Eigen::Vector2d& p,
                           double reach);

/// The x range [first, second] that holds every point of the line at height
/// `y` within `margin` (>= 0) of a 2D triangle: the triangle's x range inside
/// the slab |y' - y| <= margin, widened by margin. Empty (first > second) when
/// the line passes farther. Scanning rasters row by row over it keeps the work
/// near the triangle's area, also for long thin triangles lying diagonally.
std::pair<double, double> TriangleRowSpan(const std::array<Eigen::Vector2d, 3>& corners, double y,
                                          double margin);

}  // namespace texlume::mesh
