#include "sfm/alignment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "datasets_synthetic/object_scene.h"

namespace texlume::sfm {
namespace {

// Cameras upright in a world whose up is `up`, at `azimuths_deg` on a ring around
// the origin (azimuth 0 along +X), slightly above it, looking at the origin.
Reconstruction RingOfUprightCameras(const Eigen::Vector3d& up,
                                    const std::vector<double>& azimuths_deg,
                                    double roll_deg = 0.0) {
  const Eigen::Vector3d ex = up.unitOrthogonal(), ey = up.cross(ex);
  Reconstruction r;
  std::uint32_t id = 1;
  for (double azimuth_deg : azimuths_deg) {
    const double a = azimuth_deg * M_PI / 180.0;
    const Eigen::Vector3d centre = 3.0 * (std::cos(a) * ex + std::sin(a) * ey) + 0.5 * up;
    const Eigen::Vector3d forward = (-centre).normalized();
    const Eigen::Vector3d right = forward.cross(up).normalized();
    Eigen::Matrix3d rotation;  // rows: the camera's x (right), y (down), z (forward)
    rotation.row(0) = right;
    rotation.row(1) = forward.cross(right);
    rotation.row(2) = forward;
    rotation = Eigen::AngleAxisd(roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * rotation;
    Image image;
    image.name = "image_" + std::to_string(id) + ".png";
    image.cam_from_world.rotation = Eigen::Quaterniond(rotation);
    image.cam_from_world.translation = -(rotation * centre);
    r.images.emplace(ImageId(id++), image);
  }
  return r;
}

TEST(OrientationFromCameras, UpIsTheCamerasUpAndFrontTheSideTheyStoodOn) {
  const Eigen::Vector3d up = Eigen::Vector3d(0.2, -1.0, 0.3).normalized();
  const Eigen::Vector3d ex = up.unitOrthogonal();
  // A facade: photos from -40 to +40 degrees around ex, each rolled a little.
  const Reconstruction facade = RingOfUprightCameras(up, {-40, -20, 0, 20, 40});
  const ViewingOrientation o = OrientationFromCameras(facade, Eigen::Vector3d::Zero());
  EXPECT_LT((o.up - up).norm(), 1e-9) << o.up.transpose();
  EXPECT_LT((o.front - ex).norm(), 1e-9) << o.front.transpose();
  // Rolls of +-5 degrees tilt up by well under a degree.
  Reconstruction rolled = RingOfUprightCameras(up, {-40, 40}, 5.0);
  const Reconstruction other = RingOfUprightCameras(up, {-40, 40}, -5.0);
  for (const auto& [id, image] : other.images) rolled.images.emplace(ImageId(id.value + 10), image);
  const Eigen::Vector3d rolled_up = OrientationFromCameras(rolled, Eigen::Vector3d::Zero()).up;
  EXPECT_LT(std::acos(std::min(1.0, rolled_up.dot(up))) * 180.0 / M_PI, 1.0);
  // Photos side by side, all facing one way: x axes parallel, up from their mean.
  const Reconstruction parallel = RingOfUprightCameras(up, {0, 0, 0});
  EXPECT_LT((OrientationFromCameras(parallel, Eigen::Vector3d::Zero()).up - up).norm(), 0.2);
}

TEST(OrientationFromCameras, AFullRingFacesTheFirstPhotoAndNoPhotosKeepColmapsConvention) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<double> azimuths;
  for (int k = 0; k < 12; ++k) azimuths.push_back(90.0 + 30.0 * k);
  const ViewingOrientation o =
      OrientationFromCameras(RingOfUprightCameras(up, azimuths), Eigen::Vector3d::Zero());
  EXPECT_LT((o.up - up).norm(), 1e-9);
  EXPECT_NEAR(o.front.dot(up), 0.0, 1e-12);
  const Eigen::Vector3d first = up.cross(up.unitOrthogonal());  // azimuth 90 degrees
  EXPECT_LT((o.front - first).norm(), 1e-9) << o.front.transpose();
  const ViewingOrientation none = OrientationFromCameras(Reconstruction(), Eigen::Vector3d::Zero());
  EXPECT_EQ(none.up, -Eigen::Vector3d::UnitY());
  EXPECT_EQ(none.front, -Eigen::Vector3d::UnitZ());
}

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
