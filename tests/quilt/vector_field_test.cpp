#include "quilt/vector_field.h"

#include <gtest/gtest.h>

#include <numbers>

#include "core/errors.h"
#include "datasets_synthetic/shapes.h"
#include "quilt/surface_quilting.h"
#include "tests/test_util.h"

namespace texlume::quilt {
namespace {

Eigen::Vector3d FaceNormal(const mesh::TriangleMesh& m, std::size_t f) {
  const auto& v = m.faces[f];
  const Eigen::Vector3d& a = m.vertices[static_cast<std::size_t>(v[0])];
  return (m.vertices[static_cast<std::size_t>(v[1])] - a)
      .cross(m.vertices[static_cast<std::size_t>(v[2])] - a)
      .normalized();
}

// Key faces keep their own vectors (laid onto their planes); every face gets a
// unit vector in its plane.
TEST(InterpolateField, KeysKeepTheirVectorsAndEveryFaceLiesInItsPlane) {
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(2, 1.0);
  const std::vector<KeyVector> keys = {{0, {1, 0, 0}}, {100, {0, 1, 0}}, {250, {0, 0, 1}}};
  const std::vector<Eigen::Vector3d> field = InterpolateField(sphere, keys);
  ASSERT_EQ(field.size(), sphere.faces.size());
  for (const KeyVector& k : keys) {
    const Eigen::Vector3d n = FaceNormal(sphere, static_cast<std::size_t>(k.face));
    const Eigen::Vector3d expected =
        (k.direction_in_world - k.direction_in_world.dot(n) * n).normalized();
    EXPECT_LT((field[static_cast<std::size_t>(k.face)] - expected).norm(), 1e-6);
  }
  for (std::size_t f = 0; f < field.size(); ++f) {
    EXPECT_NEAR(field[f].norm(), 1.0, 1e-9);
    EXPECT_LT(std::abs(field[f].dot(FaceNormal(sphere, f))), 1e-9);
  }
}

// One key on a plane orients every face alike.
TEST(InterpolateField, OneKeyOnAPlaneIsEverywhere) {
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(4, 1.0);
  const std::vector<Eigen::Vector3d> field = InterpolateField(plane, {{5, {1, 1, 0.3}}});
  for (const Eigen::Vector3d& v : field)
    EXPECT_LT((v - Eigen::Vector3d(1, 1, 0).normalized()).norm(), 1e-9);
}

TEST(ReadFieldFile, RefusesWhatItCannotUseNamingTheFile) {
  testing::TempDir tmp;
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(2, 1.0);  // 8 faces, normal +z
  const auto refused = [&](const std::string& text, const std::string& words) {
    const std::filesystem::path file = tmp / "field.json";
    testing::WriteText(file, text);
    try {
      ReadFieldFile(file, plane);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field.json"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused(R"({"format": "texlume-field", "vectors": [{"face": 8, "direction": [1, 0, 0]}]})",
          "has 8 faces");
  refused(R"({"format": "texlume-field", "vectors": [{"face": 1, "direction": [0, 0, 0]}]})",
          "zero");
  refused(R"({"format": "texlume-field", "vectors": [{"face": 1, "direction": [0, 0, 2]}]})",
          "normal");
  refused(R"({"format": "texlume-field", "vectors": []})", "no vectors");
  refused(R"({"format": "texlume-field", "vectors": [{"face": -1, "direction": [1, 0, 0]}]})",
          "names face -1");
  refused(R"({"vectors": []})", "not a field file");
  refused(R"({"format": "texlume-field", "vectors": [{"face": 1, "direction": [1, 0]}]})",
          "3-vector");
  testing::WriteText(
      tmp / "good.json",
      R"({"format": "texlume-field", "vectors": [{"face": 3, "direction": [0, 2, 0]}]})");
  const std::vector<KeyVector> keys = ReadFieldFile(tmp / "good.json", plane);
  ASSERT_EQ(keys.size(), 1u);
  EXPECT_EQ(keys[0].face, 3);
}

}  // namespace
}  // namespace texlume::quilt
