#include "sfm/alignment.h"

#include <gtest/gtest.h>

#include "datasets_synthetic/object_scene.h"

namespace texlume::sfm {
namespace {

TEST(Alignment, RecoversAKnownSimilarity) {
  datasets::ObjectSceneOptions o;
  o.num_points = 0;
  const Reconstruction truth = datasets::MakeObjectScene(o).reconstruction;
  // estimate = truth seen through x_est = (R x_ref + t) / s, i.e. reference_from_estimate
  // is x_ref = s R^T (x_est - t / s).
  const double s = 2.5;
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.3, -1.0, 4.0);
  Reconstruction estimate = truth;
  for (auto& [id, image] : estimate.images) {
    const Eigen::Vector3d c = (r * image.ProjectionCenter() + t) / s;
    const Eigen::Matrix3d rot = image.cam_from_world.rotation.toRotationMatrix() * r.transpose();
    image.cam_from_world.rotation = Eigen::Quaterniond(rot);
    image.cam_from_world.translation = -(rot * c);
  }
  const SimilarityAlignment a = AlignByCameraCenters(truth, estimate);
  EXPECT_NEAR(a.scale, s, 1e-9);
  EXPECT_LT(a.rms_center_error, 1e-9);
  EXPECT_LT(a.max_rotation_error_deg, 1e-6);
  EXPECT_EQ(a.num_matched, truth.images.size());
  estimate.images.clear();
  EXPECT_THROW(AlignByCameraCenters(truth, estimate), std::invalid_argument);
}

}  // namespace
}  // namespace texlume::sfm
