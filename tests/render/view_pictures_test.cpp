#include "render/view_pictures.h"

#include <gtest/gtest.h>

namespace texlume::render {
namespace {

// A pinhole camera 10 units from a point sees one pixel span depth / focal there; the
// same camera scaled to half the size spans twice as much; a point behind has no scale.
TEST(WorldPerPixelAt, IsTheDepthOverTheFocalLength) {
  sfm::Camera camera;
  camera.model = sfm::CameraModelId::kPinhole;
  camera.width = 640;
  camera.height = 480;
  camera.params = {400.0, 600.0, 320.0, 240.0};
  sfm::Rigid3d cam_from_world;
  cam_from_world.translation = Eigen::Vector3d(0.0, 0.0, 10.0);
  const Eigen::Vector3d point(1.0, -2.0, 0.0);
  EXPECT_DOUBLE_EQ(WorldPerPixelAt(camera, cam_from_world, point), 10.0 / 500.0);
  EXPECT_DOUBLE_EQ(WorldPerPixelAt(camera.Scaled(0.5), cam_from_world, point), 10.0 / 250.0);
  EXPECT_EQ(WorldPerPixelAt(camera, cam_from_world, Eigen::Vector3d(0.0, 0.0, -11.0)), 0.0);
}

}  // namespace
}  // namespace texlume::render
