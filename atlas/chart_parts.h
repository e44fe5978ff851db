#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "atlas/charts.h"
#include "mesh/mesh.h"

// Geometry the chart makers share (synth/charts.cpp: rigid and conformal
// charts; synth/strip_charts.cpp: strips and fans).
namespace texlume::atlas::chart_parts {

inline constexpr double kPi = 3.14159265358979323846;

using Corners = std::array<Eigen::Vector2d, 3>;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

/// The face's corners in its frame, in texels.
Corners FrameCornersTexels(const synth::TrianglePatch& patch, double t);

/// The affine map taking corners `from` to corners `to`: to = m * from + b.
ChartFace AffineBetween(int face, const Corners& from, const Corners& to);

/// The faces around each vertex.
std::vector<std::vector<int>> FacesOfVertex(const mesh::TriangleMesh& mesh);

/// A chart from faces' corners in band texels (placements in world units).
std::vector<ChartFace> ChartOfBand(const std::vector<synth::TrianglePatch>& patches, double t,
                                   const std::vector<std::pair<int, Corners>>& band);

/// The smallest and largest x of the faces' corners.
std::pair<double, double> XRange(const std::vector<std::pair<int, Corners>>& faces);

/// Seeds in breadth-first order over the faces (mesh::BreadthFirstFaceOrder from
/// face 0), so each new chart starts at the border of the charted region.
std::vector<int> SeedOrder(const mesh::TriangleMesh& mesh,
                           const std::vector<std::array<synth::Unfolding, 3>>& unfoldings);

}  // namespace texlume::atlas::chart_parts
