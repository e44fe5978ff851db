#include "sfm/alignment.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace texlume::sfm {

SimilarityAlignment AlignByCameraCenters(const Reconstruction& reference,
                                         const Reconstruction& estimate) {
  std::map<std::string, const Image*> by_name;
  for (const auto& [id, image] : reference.images) by_name[image.name] = &image;
  std::vector<std::pair<const Image*, const Image*>> pairs;  // (reference, estimate)
  for (const auto& [id, image] : estimate.images) {
    const auto it = by_name.find(image.name);
    if (it != by_name.end()) pairs.emplace_back(it->second, &image);
  }
  if (pairs.size() < 3) {
    throw std::invalid_argument("alignment needs at least 3 images common to both models, found " +
                                std::to_string(pairs.size()));
  }
  Eigen::Matrix3Xd src(3, static_cast<Eigen::Index>(pairs.size()));
  Eigen::Matrix3Xd dst(3, static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    dst.col(static_cast<Eigen::Index>(i)) = pairs[i].first->ProjectionCenter();
    src.col(static_cast<Eigen::Index>(i)) = pairs[i].second->ProjectionCenter();
  }
  const Eigen::Matrix4d t = Eigen::umeyama(src, dst, true);
  SimilarityAlignment a;
  a.num_matched = pairs.size();
  a.scale = t.block<3, 1>(0, 0).norm();
  a.rotation = t.block<3, 3>(0, 0) / a.scale;
  a.translation = t.block<3, 1>(0, 3);
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector3d aligned =
        a.scale * a.rotation * src.col(static_cast<Eigen::Index>(i)) + a.translation;
    const double e = (aligned - dst.col(static_cast<Eigen::Index>(i))).norm();
    sum_sq += e * e;
    a.max_center_error = std::max(a.max_center_error, e);
    // R_ref_cam_from_world should equal R_est_cam_from_world * rotation^T.
    const Eigen::Matrix3d r_ref = pairs[i].first->cam_from_world.rotation.toRotationMatrix();
    const Eigen::Matrix3d r_est =
        pairs[i].second->cam_from_world.rotation.toRotationMatrix() * a.rotation.transpose();
    const double angle = Eigen::AngleAxisd(r_ref * r_est.transpose()).angle();
    a.max_rotation_error_deg = std::max(a.max_rotation_error_deg, angle * 180.0 / M_PI);
  }
  a.rms_center_error = std::sqrt(sum_sq / static_cast<double>(pairs.size()));
  return a;
}

Reconstruction TransformedIntoReference(const Reconstruction& estimate,
                                        const SimilarityAlignment& a) {
  Reconstruction out = estimate;
  const Eigen::Matrix3d est_from_ref_rotation = a.rotation.transpose();
  for (auto& [id, image] : out.images) {
    // x_cam' = s (R_c R^T (x_ref - t) / s + t_c) = R_c R^T x_ref + s t_c - R_c R^T t.
    const Eigen::Matrix3d rotation =
        image.cam_from_world.rotation.toRotationMatrix() * est_from_ref_rotation;
    image.cam_from_world.translation =
        a.scale * image.cam_from_world.translation - rotation * a.translation;
    image.cam_from_world.rotation = Eigen::Quaterniond(rotation).normalized();
  }
  for (auto& [id, point] : out.points3d)
    point.xyz = a.scale * a.rotation * point.xyz + a.translation;
  return out;
}

Eigen::Matrix3d ViewingOrientation::HemisphereFromWorld() const {
  const Eigen::Vector3d z = up.normalized();
  const Eigen::Vector3d x = (front - z * z.dot(front)).normalized();
  Eigen::Matrix3d rows;
  rows.row(0) = x;
  rows.row(1) = z.cross(x);
  rows.row(2) = z;
  return rows;
}

ViewingOrientation OrientationFromCameras(const Reconstruction& reconstruction,
                                          const Eigen::Vector3d& centre) {
  ViewingOrientation o;
  if (reconstruction.images.empty()) return o;
  const auto n = static_cast<double>(reconstruction.images.size());
  Eigen::Vector3d up_sum = Eigen::Vector3d::Zero(), toward_sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d right_scatter = Eigen::Matrix3d::Zero();
  for (const auto& [id, image] : reconstruction.images) {
    // Rows 0 and 1 of R_cam_from_world: the camera's x (right) and y (down) in the world.
    const Eigen::Matrix3d rotation = image.cam_from_world.rotation.toRotationMatrix();
    right_scatter += rotation.row(0).transpose() * rotation.row(0);
    up_sum -= rotation.row(1).transpose();
    toward_sum += (image.ProjectionCenter() - centre).stableNormalized();
  }
  if (!(up_sum.norm() > 1e-9)) return o;
  // Upright photos have horizontal x axes whatever their pitch: up is the direction
  // most orthogonal to all of them, when they turn enough to span a plane (about 6
  // degrees RMS); otherwise the mean up, made orthogonal to their common x axis.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(right_scatter / n);
  if (eigen.eigenvalues()(1) > 0.01) {
    o.up = eigen.eigenvectors().col(0);
    if (o.up.dot(up_sum) < 0.0) o.up = -o.up;
  } else {
    const Eigen::Vector3d right = eigen.eigenvectors().col(2);
    o.up = (up_sum - right * right.dot(up_sum)).normalized();
  }
  Eigen::Vector3d toward = toward_sum / n;
  if (toward.norm() < 0.5)
    toward = (reconstruction.images.begin()->second.ProjectionCenter() - centre).stableNormalized();
  Eigen::Vector3d front = toward - o.up * o.up.dot(toward);
  if (!(front.norm() > 1e-6)) front = o.up.unitOrthogonal();  // seen from straight above
  o.front = front.normalized();
  return o;
}

}  // namespace texlume::sfm
