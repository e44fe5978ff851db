#include "synth/triangle_frame.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace texlume::synth
