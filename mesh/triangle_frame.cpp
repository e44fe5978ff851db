#include "mesh/triangle_frame.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace texlume::mesh {

TriangleFrame MakeTriangleFrame(const mesh::TriangleMesh& mesh, std::size_t face) {
  return MakeTriangleFrame(mesh, face, mesh.Corner(face, 1) - mesh.Corner(face, 0));
}

TriangleFrame MakeTriangleFrame(const mesh::TriangleMesh& mesh, std::size_t face,
                                const Eigen::Vector3d& tangent_in_world) {
  const Eigen::Vector3d& v0 = mesh.Corner(face, 0);
  const Eigen::Vector3d& v1 = mesh.Corner(face, 1);
  const Eigen::Vector3d& v2 = mesh.Corner(face, 2);
  TriangleFrame frame;
  frame.origin_in_world = (v0 + v1 + v2) / 3.0;
  frame.z_axis = (v1 - v0).cross(v2 - v0).normalized();
  Eigen::Vector3d x = tangent_in_world - frame.z_axis * frame.z_axis.dot(tangent_in_world);
  if (x.norm() < 1e-9 * std::max(1.0, tangent_in_world.norm())) {
    x = (v1 - v0) - frame.z_axis * frame.z_axis.dot(v1 - v0);
  }
  frame.x_axis = x.normalized();
  frame.y_axis = frame.z_axis.cross(frame.x_axis);
  return frame;
}

double DistanceToSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                         const Eigen::Vector2d& p) {
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (a + s * ab - p).norm();
}

namespace {

double SquaredDistanceToSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                const Eigen::Vector2d& p) {
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return (a + s * ab - p).squaredNorm();
}

// Whether p is inside the triangle (edges included), either winding.
bool InsideTriangle(const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p) {
  const double orientation =
      (c[1] - c[0]).x() * (c[2] - c[0]).y() - (c[1] - c[0]).y() * (c[2] - c[0]).x();
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d& a = c[k];
    const Eigen::Vector2d& b = c[(k + 1) % 3];
    const double cross = (b - a).x() * (p - a).y() - (b - a).y() * (p - a).x();
    if (cross * orientation < 0) return false;
  }
  return true;
}

// The distance to the nearest edge: the square root of the least squared
// distance, which is the least of the distances to the edges exactly; the
// largest double when no distance is finite (NaN or overflowing corners).
double DistanceToEdges(const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  double nearest = kInfinity;
  for (std::size_t k = 0; k < 3; ++k)
    nearest = std::min(nearest, SquaredDistanceToSegment(c[k], c[(k + 1) % 3], p));
  return nearest == kInfinity ? std::numeric_limits<double>::max() : std::sqrt(nearest);
}

}  // namespace

double SignedDistanceToTriangle(const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p) {
  return InsideTriangle(c, p) ? -DistanceToEdges(c, p) : DistanceToEdges(c, p);
}

bool WithinReachOfTriangle(const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p,
                           double reach) {
  return InsideTriangle(c, p) || DistanceToEdges(c, p) <= reach;
}

std::pair<double, double> TriangleRowSpan(const std::array<Eigen::Vector2d, 3>& c, double y,
                                          double margin) {
  const double y_lo = y - margin, y_hi = y + margin;
  double lo = std::numeric_limits<double>::max(), hi = -lo;
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d& a = c[k];
    const Eigen::Vector2d& b = c[(k + 1) % 3];
    if (a.y() >= y_lo && a.y() <= y_hi) lo = std::min(lo, a.x()), hi = std::max(hi, a.x());
    for (const double line : {y_lo, y_hi})
      if ((a.y() - line) * (b.y() - line) < 0.0) {
        const double x = a.x() + (line - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
        lo = std::min(lo, x), hi = std::max(hi, x);
      }
  }
  if (lo > hi) return {1.0, 0.0};
  return {lo - margin, hi + margin};
}

}  // namespace texlume::mesh
