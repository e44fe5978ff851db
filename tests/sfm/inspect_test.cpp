#include "sfm/inspect.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "datasets_synthetic/object_scene.h"
#include "tests/test_util.h"

namespace texlume::sfm {
namespace {

using testing::TempDir;

TEST(Inspect, ReportsModelMeshVisibilityLightsAndMissingImages) {
  TempDir tmp;
  datasets::ObjectSceneOptions options;
  options.num_images = 8;
  const datasets::ObjectScene scene = datasets::MakeObjectScene(options);
  datasets::WriteObjectScene(scene, tmp.path());
  std::filesystem::create_directories(tmp / "images");
  testing::WriteText(tmp / "images" / "image_000.png", "not checked for content");

  InspectOptions inspect;
  inspect.model_dir = tmp / "sparse_txt";
  inspect.mesh = tmp / "mesh.ply";
  inspect.lights = tmp / "lights.json";
  inspect.images_dir = tmp / "images";
  const InspectReport report = RunInspect(inspect);
  EXPECT_EQ(report.format, ModelFormat::kText);
  EXPECT_EQ(report.num_images, 8u);
  EXPECT_EQ(report.num_points3d, scene.reconstruction.points3d.size());
  EXPECT_EQ(report.num_observations, scene.reconstruction.NumObservations());
  EXPECT_EQ(report.mesh_stats->faces, scene.mesh.NumFaces());
  EXPECT_EQ(
      *report.triangles_fully_seen + *report.triangles_partially_seen + *report.triangles_unseen,
      scene.mesh.NumFaces());
  EXPECT_GT(*report.triangles_fully_seen, scene.mesh.NumFaces() * 8 / 10);
  EXPECT_EQ(report.missing_images->size(), 7u);
  EXPECT_EQ(report.num_lit_images, 8u);
  const std::string text = FormatInspectReport(report);
  EXPECT_NE(text.find("Images missing on disk: 7"), std::string::npos) << text;
  EXPECT_NE(text.find("Triangles fully seen by >= 1 photo"), std::string::npos);
  EXPECT_NE(InspectReportToJson(report).find("\"missing_images\""), std::string::npos);
}

TEST(Inspect, LpLightsForUnknownImagesAreRefused) {
  TempDir tmp;
  datasets::ObjectSceneOptions options;
  options.num_images = 3;
  options.num_points = 0;
  datasets::WriteObjectScene(datasets::MakeObjectScene(options), tmp.path());
  testing::WriteText(tmp / "lights.lp", "2\nimage_000.png 0 0 1\nother.png 0 0 1\n");
  InspectOptions inspect;
  inspect.model_dir = tmp / "sparse";
  inspect.lights = tmp / "lights.lp";
  try {
    RunInspect(inspect);
    FAIL() << "accepted lights for an unknown image";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("other.png"), std::string::npos);
  }
}

TEST(InspectOptions, AMissingModelFolderOrBadNestedSettingIsRefused) {
  InspectOptions o;
  EXPECT_THROW(o.Check(), OptionError);  // no model folder
  o.model_dir = "model";
  EXPECT_NO_THROW(o.Check());
  o.visibility.edge_samples = 100;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(RunInspect(o), OptionError);
}

}  // namespace
}  // namespace texlume::sfm
