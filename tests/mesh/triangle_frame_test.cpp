#include "mesh/triangle_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "synth/mesh_synthesis.h"

namespace texlume::synth {
namespace {

TEST(TriangleFrame, AxesFollowPaper003Section302) {
  mesh::TriangleMesh mesh;
  mesh.vertices = {{1, 1, 1}, {3, 1, 1}, {1, 1, 4}};
  mesh.faces = {{0, 1, 2}};
  const mesh::TriangleFrame frame = mesh::MakeTriangleFrame(mesh, 0);
  EXPECT_TRUE(frame.origin_in_world.isApprox(Eigen::Vector3d(5.0 / 3, 1, 2)));
  EXPECT_TRUE(frame.x_axis.isApprox(Eigen::Vector3d(1, 0, 0)));   // along v0 -> v1
  EXPECT_TRUE(frame.z_axis.isApprox(Eigen::Vector3d(0, -1, 0)));  // (v1-v0) x (v2-v0)
  EXPECT_TRUE(frame.y_axis.isApprox(frame.z_axis.cross(frame.x_axis)));
  // A light along the normal is (lu, lv) = (0, 0) in the frame.
  EXPECT_TRUE(frame.DirectionInFrame(-Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(frame.PointInFrame(frame.origin_in_world).isZero());
}

TEST(TriangleFrame, TangentFieldReplacesTheFirstEdge) {
  mesh::TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  const mesh::TriangleFrame frame = mesh::MakeTriangleFrame(mesh, 0, Eigen::Vector3d(1, 1, 5));
  EXPECT_TRUE(frame.x_axis.isApprox(Eigen::Vector3d(1, 1, 0).normalized()));
  EXPECT_TRUE(frame.z_axis.isApprox(Eigen::Vector3d(0, 0, 1)));
  // A tangent along the normal falls back to v0 -> v1.
  EXPECT_TRUE(mesh::MakeTriangleFrame(mesh, 0, Eigen::Vector3d(0, 0, 1))
                  .x_axis.isApprox(Eigen::Vector3d(1, 0, 0)));
}

TEST(RelightMixture, LightsBelowTheHorizonElevationFadeToZero) {
  // A texel brighter towards grazing lights: L = 0.3 + 0.5 lu^2 (a0 lu^2).
  const float a[6] = {0.5f, 0.0f, 0.0f, 0.0f, 0.0f, 0.3f};
  const float colour[3] = {1.0f, 1.0f, 1.0f};
  auto at = [&](double elevation_deg) {
    const double e = elevation_deg * std::numbers::pi / 180.0;
    const Eigen::Vector3d l(std::cos(e), 0.0, std::sin(e));
    return SrgbToLinear(RelightMixture(a, colour, ptm::PtmFormat::kLrgb, {{l, 1.0}}, 1.0, {},
                                       Eigen::Vector3d::UnitZ())[0]);
  };
  const double h = ptm::kHorizonElevationDeg * std::numbers::pi / 180.0;
  // Above the horizon elevation: the polynomial itself.
  const double l30 = std::cos(30.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(at(30.0), SrgbToLinear(static_cast<float>(0.3 + 0.5 * l30 * l30)), 1e-4);
  // Below: the value at the horizon elevation times l_z / sin(elevation); 0 at and below 0.
  const double at_h = at(ptm::kHorizonElevationDeg);
  EXPECT_NEAR(at(5.0), at_h * std::sin(5.0 * std::numbers::pi / 180.0) / std::sin(h), 1e-4);
  EXPECT_NEAR(at(ptm::kHorizonElevationDeg - 1e-6), at_h, 1e-4);
  EXPECT_EQ(at(-5.0), 0.0f);
  EXPECT_LT(at(2.0), at(10.0));
}

// The row span holds every point of the row within the margin of the
// triangle (sampled densely), and no more than the margin beyond the points
// of the triangle in the slab: a long thin triangle lying diagonally spans a
// short stretch of each row, not its bounding box.
TEST(TriangleRowSpan, HoldsThePointsWithinTheMarginAndLittleMore) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  for (int trial = 0; trial < 200; ++trial) {
    // Drawn one at a time, last first: a call's arguments are evaluated in an
    // unspecified order (GCC right to left, clang left to right).
    std::array<Eigen::Vector2d, 3> c;
    for (Eigen::Vector2d& corner : c) {
      const double y = u(rng), x = u(rng);
      corner = Eigen::Vector2d(x, y);
    }
    if (trial % 4 == 0) c[2] = c[0] + 0.02 * (c[1] - c[0]) + Eigen::Vector2d(0.3, -0.2);  // sliver
    const double margin = trial % 3 == 0 ? 0.0 : 2.5;
    for (double y = -60.0; y <= 60.0; y += 1.7) {
      const auto [lo, hi] = mesh::TriangleRowSpan(c, y, margin);
      for (double x = -60.0; x <= 60.0; x += 0.05)
        if (mesh::SignedDistanceToTriangle(c, Eigen::Vector2d(x, y)) <= margin - 1e-9) {
          EXPECT_GE(x, lo - 1e-9) << "trial " << trial << " y " << y;
          EXPECT_LE(x, hi + 1e-9) << "trial " << trial << " y " << y;
        }
    }
  }
  // A sliver from (0, 0) to (800, 800), 2 wide: each row spans about its
  // width plus twice the margin, not 800.
  const std::array<Eigen::Vector2d, 3> sliver = {Eigen::Vector2d(0, 0), Eigen::Vector2d(800, 800),
                                                 Eigen::Vector2d(2, 0)};
  const auto [lo, hi] = mesh::TriangleRowSpan(sliver, 400.0, 2.5);
  EXPECT_LT(hi - lo, 2.0 + 4 * 2.5 + 1e-9);
  EXPECT_GT(mesh::TriangleRowSpan(sliver, 900.0, 2.5).first,
            mesh::TriangleRowSpan(sliver, 900.0, 2.5).second);
}

}  // namespace
}  // namespace texlume::synth
