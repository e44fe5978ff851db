#include "synth/triangle_frame.h"

#include <Eigen/Geometry>

namespace texlume::synth {

TriangleFrame MakeTriangleFrame(const sfm::TriangleMesh& mesh, std::size_t face) {
  return MakeTriangleFrame(mesh, face, mesh.Corner(face, 1) - mesh.Corner(face, 0));
}

TriangleFrame MakeTriangleFrame(const sfm::TriangleMesh& mesh, std::size_t face,
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

}  // namespace texlume::synth
