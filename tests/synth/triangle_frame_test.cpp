#include "synth/triangle_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "synth/mesh_synthesis.h"

namespace texlume::synth {
namespace {

TEST(TriangleFrame, AxesFollowPaper003Section302) {
  sfm::TriangleMesh mesh;
  mesh.vertices = {{1, 1, 1}, {3, 1, 1}, {1, 1, 4}};
  mesh.faces = {{0, 1, 2}};
  const TriangleFrame frame = MakeTriangleFrame(mesh, 0);
  EXPECT_TRUE(frame.origin_in_world.isApprox(Eigen::Vector3d(5.0 / 3, 1, 2)));
  EXPECT_TRUE(frame.x_axis.isApprox(Eigen::Vector3d(1, 0, 0)));   // along v0 -> v1
  EXPECT_TRUE(frame.z_axis.isApprox(Eigen::Vector3d(0, -1, 0)));  // (v1-v0) x (v2-v0)
  EXPECT_TRUE(frame.y_axis.isApprox(frame.z_axis.cross(frame.x_axis)));
  // A light along the normal is (lu, lv) = (0, 0) in the frame.
  EXPECT_TRUE(frame.DirectionInFrame(-Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(frame.PointInFrame(frame.origin_in_world).isZero());
}

TEST(TriangleFrame, TangentFieldReplacesTheFirstEdge) {
  sfm::TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.faces = {{0, 1, 2}};
  const TriangleFrame frame = MakeTriangleFrame(mesh, 0, Eigen::Vector3d(1, 1, 5));
  EXPECT_TRUE(frame.x_axis.isApprox(Eigen::Vector3d(1, 1, 0).normalized()));
  EXPECT_TRUE(frame.z_axis.isApprox(Eigen::Vector3d(0, 0, 1)));
  // A tangent along the normal falls back to v0 -> v1.
  EXPECT_TRUE(MakeTriangleFrame(mesh, 0, Eigen::Vector3d(0, 0, 1))
                  .x_axis.isApprox(Eigen::Vector3d(1, 0, 0)));
}

TEST(RelightMixture, LightsBelowTheHorizonElevationFadeToZero) {
  // A texel brighter towards grazing lights: L = 0.3 + 0.5 lu^2 (a0 lu^2).
  const float a[6] = {0.5f, 0.0f, 0.0f, 0.0f, 0.0f, 0.3f};
  const float colour[3] = {1.0f, 1.0f, 1.0f};
  auto at = [&](double elevation_deg) {
    const double e = elevation_deg * std::numbers::pi / 180.0;
    const Eigen::Vector3d l(std::cos(e), 0.0, std::sin(e));
    return SrgbToLinear(RelightMixture(a, colour, ptm::PtmFormat::kLrgb, {{l, 1.0}}, 1.0)[0]);
  };
  const double h = kHorizonElevationDeg * std::numbers::pi / 180.0;
  // Above the horizon elevation: the polynomial itself.
  const double l30 = std::cos(30.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(at(30.0), SrgbToLinear(static_cast<float>(0.3 + 0.5 * l30 * l30)), 1e-4);
  // Below: the value at the horizon elevation times l_z / sin(elevation); 0 at and below 0.
  const double at_h = at(kHorizonElevationDeg);
  EXPECT_NEAR(at(5.0), at_h * std::sin(5.0 * std::numbers::pi / 180.0) / std::sin(h), 1e-4);
  EXPECT_NEAR(at(kHorizonElevationDeg - 1e-6), at_h, 1e-4);
  EXPECT_EQ(at(-5.0), 0.0f);
  EXPECT_LT(at(2.0), at(10.0));
}

}  // namespace
}  // namespace texlume::synth
