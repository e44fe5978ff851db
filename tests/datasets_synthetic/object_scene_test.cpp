#include "datasets_synthetic/object_scene.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace texlume::datasets {
namespace {

TEST(ObjectScene, SameSeedSameBytes) {
  testing::TempDir tmp;
  WriteObjectScene(MakeObjectScene({}), tmp / "a");
  WriteObjectScene(MakeObjectScene({}), tmp / "b");
  for (const std::string f : {"sparse/images.bin", "sparse/points3D.bin", "sparse_txt/cameras.txt",
                              "mesh.ply", "lights.json"}) {
    EXPECT_EQ(testing::ReadText(tmp / "a" / f), testing::ReadText(tmp / "b" / f)) << f;
  }
  ObjectSceneOptions other;
  other.seed = 2;
  WriteObjectScene(MakeObjectScene(other), tmp / "c");
  EXPECT_NE(testing::ReadText(tmp / "a" / "sparse/points3D.bin"),
            testing::ReadText(tmp / "c" / "sparse/points3D.bin"));
}

TEST(ObjectScene, ObservationsReprojectWithinTheNoiseAndCamerasFaceTheObject) {
  for (const auto model : {sfm::CameraModelId::kPinhole, sfm::CameraModelId::kOpenCV}) {
    ObjectSceneOptions options;
    options.camera_model = model;
    options.shape = SceneShape::kCylinder;
    const ObjectScene scene = MakeObjectScene(options);
    ASSERT_GT(scene.reconstruction.points3d.size(), 500u);
    double sum_sq = 0;
    std::size_t n = 0;
    for (const auto& [id, point] : scene.reconstruction.points3d) {
      ASSERT_GE(point.track.size(), 2u);
      for (const auto& e : point.track) {
        const sfm::Image& image = scene.reconstruction.images.at(e.image_id);
        const auto px = scene.reconstruction.Project(image, point.xyz);
        ASSERT_TRUE(px.has_value());
        sum_sq += (*px - image.points2d[e.point2d_idx].xy).squaredNorm();
        ++n;
      }
    }
    // Two noise components of sigma 0.3 px each: RMS distance about 0.42 px.
    EXPECT_NEAR(std::sqrt(sum_sq / static_cast<double>(n)), 0.3 * std::sqrt(2.0), 0.05);
    for (const auto& [id, image] : scene.reconstruction.images) {
      const auto center_px = scene.reconstruction.Project(image, Eigen::Vector3d::Zero());
      EXPECT_LT((*center_px - Eigen::Vector2d(320, 240)).norm(), 1e-6);
    }
  }
}

}  // namespace
}  // namespace texlume::datasets
