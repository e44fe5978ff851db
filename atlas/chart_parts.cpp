#include "atlas/chart_parts.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace texlume::atlas::chart_parts {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// The face's corners in its frame, in texels.
Corners FrameCornersTexels(const synth::TrianglePatch& patch, double t) {
  Corners c;
  for (std::size_t k = 0; k < 3; ++k) c[k] = patch.corners_in_frame[k] / t;
  return c;
}

/// The affine map taking corners `from` to corners `to`: to = m * from + b.
ChartFace AffineBetween(int face, const Corners& from, const Corners& to) {
  Eigen::Matrix2d f, g;
  f.col(0) = from[1] - from[0];
  f.col(1) = from[2] - from[0];
  g.col(0) = to[1] - to[0];
  g.col(1) = to[2] - to[0];
  ChartFace cf;
  cf.face = face;
  cf.linear = g * f.inverse();
  cf.translation = to[0] - cf.linear * from[0];
  return cf;
}

/// The faces around each vertex.
std::vector<std::vector<int>> FacesOfVertex(const mesh::TriangleMesh& mesh) {
  std::vector<std::vector<int>> faces_of_vertex(mesh.vertices.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (const int v : mesh.faces[f])
      faces_of_vertex[static_cast<std::size_t>(v)].push_back(static_cast<int>(f));
  return faces_of_vertex;
}

/// A chart from faces' corners in band texels (placements in world units).
std::vector<ChartFace> ChartOfBand(const std::vector<synth::TrianglePatch>& patches, double t,
                                   const std::vector<std::pair<int, Corners>>& band) {
  std::vector<ChartFace> chart;
  for (const auto& [f, q] : band) {
    ChartFace cf = AffineBetween(f, FrameCornersTexels(patches[static_cast<std::size_t>(f)], t), q);
    cf.translation *= t;  // texels -> world units (linear is unitless)
    chart.push_back(cf);
  }
  return chart;
}

/// The smallest and largest x of the faces' corners.
std::pair<double, double> XRange(const std::vector<std::pair<int, Corners>>& faces) {
  double lo = std::numeric_limits<double>::max(), hi = -lo;
  for (const auto& fq : faces)
    for (const auto& p : fq.second) lo = std::min(lo, p.x()), hi = std::max(hi, p.x());
  return {lo, hi};
}

/// Seeds in breadth-first order over the faces (mesh::BreadthFirstFaceOrder from
/// face 0), so each new chart starts at the border of the charted region.
std::vector<int> SeedOrder(const mesh::TriangleMesh& mesh,
                           const std::vector<std::array<synth::Unfolding, 3>>& unfoldings) {
  if (mesh.faces.empty()) return {};
  std::vector<std::array<int, 3>> neighbours(unfoldings.size());
  for (std::size_t f = 0; f < unfoldings.size(); ++f)
    for (std::size_t k = 0; k < 3; ++k) neighbours[f][k] = unfoldings[f][k].face;
  return mesh::BreadthFirstFaceOrder(mesh, neighbours, 0);
}

}  // namespace texlume::atlas::chart_parts
