#include "datasets_synthetic/object_scene.h"

#include <gtest/gtest.h>

#include <map>
#include <numbers>

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

TEST(ObjectScene, ShapeMeshWithFacesComesNearTheTarget) {
  for (const std::int64_t target : {400, 20000, 300000}) {
    for (const auto shape : {SceneShape::kCylinder, SceneShape::kPlane, SceneShape::kTorus}) {
      const mesh::TriangleMesh mesh = ShapeMeshWithFaces(shape, target);
      EXPECT_NEAR(static_cast<double>(mesh.faces.size()), static_cast<double>(target),
                  0.1 * static_cast<double>(target))
          << SceneShapeName(shape);
      // Square cells on the plane: the diagonal is the longest edge. (The torus's
      // cells narrow towards its hole; the column's cap rings are not squares.)
      double shortest = 1e9, longest = 0;
      for (std::size_t f = 0; f < mesh.faces.size(); f += 97) {
        for (int k = 0; k < 3; ++k) {
          const double edge = (mesh.Corner(f, (k + 1) % 3) - mesh.Corner(f, k)).norm();
          shortest = std::min(shortest, edge), longest = std::max(longest, edge);
        }
      }
      if (shape == SceneShape::kPlane) {
        EXPECT_NEAR(longest, std::sqrt(2.0) * shortest, 1e-9);
      }
    }
    const double sphere_faces =
        static_cast<double>(ShapeMeshWithFaces(SceneShape::kSphere, target).faces.size());
    EXPECT_GE(sphere_faces, target / 2.0);
    EXPECT_LE(sphere_faces, target * 2.0);
  }
  ObjectSceneOptions options;
  options.target_faces = 5000;
  options.num_points = 0;
  EXPECT_EQ(MakeObjectScene(options).mesh.faces.size(),
            ShapeMeshWithFaces(SceneShape::kSphere, 5000).faces.size());
}

TEST(ObjectScene, ColumnIsClosedOutwardAndWithoutSlivers) {
  const mesh::TriangleMesh column = MakeColumn(60, 20, 0.6, 1.6);
  double volume = 0;  // divergence theorem: positive when every face faces out
  double smallest_angle_deg = 180;
  for (std::size_t f = 0; f < column.faces.size(); ++f) {
    const Eigen::Vector3d a = column.Corner(f, 0), b = column.Corner(f, 1), c = column.Corner(f, 2);
    volume += a.dot(b.cross(c)) / 6.0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = column.Corner(f, k), q = column.Corner(f, (k + 1) % 3),
                            r = column.Corner(f, (k + 2) % 3);
      const double cosine = (q - p).normalized().dot((r - p).normalized());
      smallest_angle_deg = std::min(smallest_angle_deg, std::acos(cosine) * 180 / std::numbers::pi);
    }
  }
  // The prism on a 60-gon: 1.6 * (60 / 2) * 0.6^2 * sin(6 degrees).
  EXPECT_NEAR(volume, 1.6 * 30 * 0.36 * std::sin(std::numbers::pi / 30), 1e-9);
  EXPECT_GT(smallest_angle_deg, 20.0);  // a fan cap's slivers have 6 degrees
  // Closed: every edge shared by exactly two faces, once each way.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& face : column.faces)
    for (int k = 0; k < 3; ++k) ++directed[{face[k], face[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
}

TEST(ObjectScene, CameraRingsShareThePhotosOutAtTheirElevations) {
  ObjectSceneOptions options;
  options.shape = SceneShape::kCylinder;
  options.num_images = 31;
  options.camera_rings = 3;
  options.num_points = 0;
  const ObjectScene scene = MakeObjectScene(options);
  const std::vector<double> elevations = CameraRingElevations(options.shape, 3);
  ASSERT_EQ(elevations.size(), 3u);
  EXPECT_LT(elevations[0], 0.0);  // below the equator: the lower part of the column
  EXPECT_GT(elevations[2], 0.0);
  std::vector<int> on_ring(3, 0);
  for (const auto& [id, image] : scene.reconstruction.images) {
    const Eigen::Vector3d center = image.ProjectionCenter();
    const double elevation = std::asin(center.z() / center.norm());
    int ring = -1;
    for (int r = 0; r < 3; ++r)
      if (std::abs(elevation - elevations[static_cast<std::size_t>(r)]) < 1e-9) ring = r;
    ASSERT_GE(ring, 0) << "a camera off every ring, elevation " << elevation;
    ++on_ring[static_cast<std::size_t>(ring)];
    EXPECT_NEAR(center.norm(), options.camera_distance, 1e-9);
    const auto center_px = scene.reconstruction.Project(image, Eigen::Vector3d::Zero());
    ASSERT_TRUE(center_px.has_value());
    EXPECT_LT((*center_px - Eigen::Vector2d(320, 240)).norm(), 1e-6);
  }
  EXPECT_EQ(on_ring, (std::vector<int>{11, 10, 10}));
  EXPECT_EQ(scene.lights.size(), 31u);

  options.camera_rings = 32;
  EXPECT_THROW(options.Check(), OptionError);
  options.camera_rings = 1;
  options.target_faces = ObjectSceneOptions::kMaxTargetFaces + 1;
  EXPECT_THROW(options.Check(), OptionError);
}

}  // namespace
}  // namespace texlume::datasets
