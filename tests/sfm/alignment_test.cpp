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
  // Moved back into the reference frame, every camera is the truth's again
  // (up to the quaternion's sign) and projects a world point to the same pixel.
  const Reconstruction back = TransformedIntoReference(estimate, a);
  const Eigen::Vector3d x_ref(0.2, -0.4, 0.5);
  for (const auto& [id, image] : truth.images) {
    const Image& b = back.images.at(id);
    EXPECT_NEAR(b.cam_from_world.rotation.angularDistance(image.cam_from_world.rotation), 0.0,
                1e-9);
    EXPECT_LT((b.cam_from_world.translation - image.cam_from_world.translation).norm(), 1e-9);
    const Eigen::Vector3d seen = b.cam_from_world.rotation * x_ref + b.cam_from_world.translation;
    const Eigen::Vector3d x_est = a.rotation.transpose() * (x_ref - a.translation) / a.scale;
    const Image& e = estimate.images.at(id);
    const Eigen::Vector3d seen_est =
        e.cam_from_world.rotation * x_est + e.cam_from_world.translation;
    EXPECT_LT((seen.hnormalized() - seen_est.hnormalized()).norm(), 1e-9);
  }
  estimate.images.clear();
  EXPECT_THROW(AlignByCameraCenters(truth, estimate), std::invalid_argument);
}

}  // namespace
}  // namespace texlume::sfm
