#include "sfm/camera_models.h"

#include <gtest/gtest.h>

#include <random>

namespace texlume::sfm {
namespace {

Camera MakeCamera(CameraModelId model) {
  Camera c;
  c.model = model;
  c.width = 1600;
  c.height = 1200;
  switch (model) {
    case CameraModelId::kSimplePinhole:
      c.params = {1000, 800, 600};
      break;
    case CameraModelId::kPinhole:
      c.params = {1000, 1020, 805, 598};
      break;
    case CameraModelId::kSimpleRadial:
      c.params = {1000, 800, 600, -0.08};
      break;
    case CameraModelId::kRadial:
      c.params = {1000, 800, 600, -0.08, 0.02};
      break;
    case CameraModelId::kOpenCV:
      c.params = {1000, 1010, 800, 600, -0.1, 0.03, 0.001, -0.0015};
      break;
    case CameraModelId::kOpenCVFisheye:
      c.params = {600, 605, 800, 600, 0.05, -0.01, 0.003, -0.0005};
      break;
    case CameraModelId::kFullOpenCV:
      c.params = {1000, 1010, 800, 600, -0.1, 0.03, 0.001, -0.0015, 0.002, 0.01, -0.003, 0.001};
      break;
    case CameraModelId::kFov:
      c.params = {1000, 1010, 800, 600, 0.6};
      break;
    case CameraModelId::kSimpleRadialFisheye:
      c.params = {600, 800, 600, 0.04};
      break;
    case CameraModelId::kRadialFisheye:
      c.params = {600, 800, 600, 0.04, -0.005};
      break;
    case CameraModelId::kThinPrismFisheye:
      c.params = {600,   605,     800,   600,     0.04,   -0.005,
                  0.001, -0.0008, 0.002, -0.0003, 0.0007, -0.0004};
      break;
  }
  return c;
}

class CameraModelTest : public ::testing::TestWithParam<int> {};

TEST_P(CameraModelTest, ProjectUnprojectRoundTripBelowMicroPixel) {
  const Camera camera = MakeCamera(CameraModelId(GetParam()));
  ASSERT_NO_THROW(camera.Check());
  std::mt19937 rng(42 + GetParam());
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::uniform_real_distribution<double> depth(0.5, 20.0);
  double worst_px = 0.0, worst_ray = 0.0;
  for (int i = 0; i < 2000; ++i) {
    const double z = depth(rng);
    // Drawn one at a time, last first: a call's arguments are evaluated in an
    // unspecified order (GCC right to left, clang left to right).
    const double v = u(rng), w = u(rng);
    const Eigen::Vector3d point_in_cam(w * z, v * z * 0.75, z);
    const auto pixel = camera.ImageFromCam(point_in_cam);
    ASSERT_TRUE(pixel.has_value());
    const Eigen::Vector3d ray = camera.CamRayFromImage(*pixel);
    EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
    worst_ray = std::max(worst_ray, (ray - point_in_cam.normalized()).norm());
    const auto again = camera.ImageFromCam(ray * 3.0);
    ASSERT_TRUE(again.has_value());
    worst_px = std::max(worst_px, (*again - *pixel).norm());
  }
  EXPECT_LT(worst_px, 1e-6) << CameraModelName(camera.model);
  EXPECT_LT(worst_ray, 1e-9) << CameraModelName(camera.model);
}

TEST_P(CameraModelTest, UnprojectProjectFromPixelsAcrossTheImage) {
  const Camera camera = MakeCamera(CameraModelId(GetParam()));
  for (double y = 0.0; y <= 1200.0; y += 100.0) {
    for (double x = 0.0; x <= 1600.0; x += 100.0) {
      const Eigen::Vector3d ray = camera.CamRayFromImage({x, y});
      const auto pixel = camera.ImageFromCam(ray);
      ASSERT_TRUE(pixel.has_value());
      EXPECT_LT((*pixel - Eigen::Vector2d(x, y)).norm(), 1e-6)
          << CameraModelName(camera.model) << " at " << x << "," << y;
    }
  }
}

TEST_P(CameraModelTest, ScaledCameraProjectsToScaledPixels) {
  const Camera camera = MakeCamera(CameraModelId(GetParam()));
  const Camera twice = camera.Scaled(2.0);
  ASSERT_NO_THROW(twice.Check());
  EXPECT_EQ(twice.width, 2 * camera.width);
  EXPECT_EQ(twice.height, 2 * camera.height);
  for (double y = 0.0; y <= 1200.0; y += 200.0) {
    for (double x = 0.0; x <= 1600.0; x += 200.0) {
      const Eigen::Vector3d ray = camera.CamRayFromImage({x, y});
      const auto pixel = twice.ImageFromCam(ray);
      ASSERT_TRUE(pixel.has_value());
      EXPECT_LT((*pixel - Eigen::Vector2d(2 * x, 2 * y)).norm(), 1e-6)
          << CameraModelName(camera.model) << " at " << x << "," << y;
    }
  }
  EXPECT_THROW(camera.Scaled(0.0), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(AllColmapModels, CameraModelTest, ::testing::Range(0, kNumCameraModels),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return std::string(CameraModelName(CameraModelId(param_info.param)));
                         });

TEST(CameraModels, NamesIdsAndParameterCountsMatchColmap) {
  const std::vector<std::pair<std::string, int>> expected = {{"SIMPLE_PINHOLE", 3},
                                                             {"PINHOLE", 4},
                                                             {"SIMPLE_RADIAL", 4},
                                                             {"RADIAL", 5},
                                                             {"OPENCV", 8},
                                                             {"OPENCV_FISHEYE", 8},
                                                             {"FULL_OPENCV", 12},
                                                             {"FOV", 5},
                                                             {"SIMPLE_RADIAL_FISHEYE", 4},
                                                             {"RADIAL_FISHEYE", 5},
                                                             {"THIN_PRISM_FISHEYE", 12}};
  for (int id = 0; id < kNumCameraModels; ++id) {
    EXPECT_EQ(CameraModelName(CameraModelId(id)), expected[static_cast<std::size_t>(id)].first);
    EXPECT_EQ(CameraModelNumParams(CameraModelId(id)),
              expected[static_cast<std::size_t>(id)].second);
    EXPECT_EQ(CameraModelFromName(expected[static_cast<std::size_t>(id)].first), CameraModelId(id));
  }
  EXPECT_FALSE(IsValidCameraModelId(11));
  EXPECT_FALSE(IsValidCameraModelId(-1));
  EXPECT_FALSE(CameraModelFromName("PINHOLEX").has_value());
  EXPECT_THROW(CameraModelName(CameraModelId(42)), std::invalid_argument);
}

TEST(CameraModels, PinholeKnownAnswerAndPixelConvention) {
  Camera camera = MakeCamera(CameraModelId::kPinhole);
  camera.params = {500, 400, 320, 240};
  // The principal point maps the optical axis; COLMAP's pixel convention puts the
  // centre of the top-left pixel at (0.5, 0.5).
  EXPECT_TRUE(camera.ImageFromCam({0, 0, 2})->isApprox(Eigen::Vector2d(320, 240)));
  EXPECT_TRUE(camera.ImageFromCam({1, -1, 2})->isApprox(Eigen::Vector2d(570, 40)));
  EXPECT_FALSE(camera.ImageFromCam({0, 0, -1}).has_value());
  EXPECT_FALSE(camera.ImageFromCam({0, 0, 0}).has_value());
}

TEST(CameraModels, OpenCVDistortionKnownAnswer) {
  // u = (0.1, -0.2): r2 = 0.05, radial = k1 r2 + k2 r4.
  const std::vector<double> p = {1, 1, 0, 0, -0.1, 0.03, 0.001, -0.002};
  const double x = 0.1, y = -0.2, r2 = 0.05, radial = -0.1 * r2 + 0.03 * r2 * r2;
  const Eigen::Vector2d expected(x + x * radial + 2 * 0.001 * x * y + -0.002 * (r2 + 2 * x * x),
                                 y + y * radial + 2 * -0.002 * x * y + 0.001 * (r2 + 2 * y * y));
  EXPECT_TRUE(DistortNormalized(CameraModelId::kOpenCV, p, {x, y}).isApprox(expected, 1e-15));
}

TEST(CameraModels, FisheyeIsEquidistantWithoutDistortion) {
  Camera camera = MakeCamera(CameraModelId::kOpenCVFisheye);
  camera.params = {500, 500, 0, 0, 0, 0, 0, 0};
  // A ray at 60 degrees from the axis lands at radius f * theta.
  const double theta = 60.0 * M_PI / 180.0;
  const auto px = camera.ImageFromCam({std::sin(theta), 0, std::cos(theta)});
  EXPECT_NEAR(px->x(), 500 * theta, 1e-9);
}

TEST(CameraModels, CheckRejectsWrongParameterCountAndFocal) {
  Camera camera = MakeCamera(CameraModelId::kPinhole);
  camera.params.pop_back();
  EXPECT_THROW(camera.Check(), std::invalid_argument);
  camera = MakeCamera(CameraModelId::kPinhole);
  camera.params[0] = -1;
  EXPECT_THROW(camera.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace texlume::sfm
