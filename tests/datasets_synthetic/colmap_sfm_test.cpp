// COLMAP's own structure from motion (CPU) on a generated object photo set: it must
// register nearly all photos, and its cameras must align to the ground truth.
#include <gtest/gtest.h>

#include "datasets_synthetic/scene.h"
#include "sfm/alignment.h"
#include "sfm/colmap_io.h"
#include "tests/colmap_runner.h"
#include "tests/test_util.h"

namespace texlume::datasets {
namespace {

TEST(ColmapSfm, RegistersTheGeneratedPhotosAndAlignsToGroundTruth) {
  if (!TEXLUME_COLMAP_TESTS) GTEST_SKIP() << "TEXLUME_COLMAP_TESTS is OFF";
  testing::TempDir tmp;
  SceneOptions options;  // sphere, stone, 36 photos of 640 x 480
  options.capture_size = 32;
  options.num_capture_lights = 6;
  options.num_held_out_capture_lights = 0;
  options.write_btf = false;
  options.num_held_out_views = 0;
  GenerateScene(options, tmp / "scene");
  const std::filesystem::path sparse =
      testing::RunColmapSfm(tmp / "scene/object/images", tmp.path());
  ASSERT_FALSE(sparse.empty());
  const sfm::Reconstruction truth = sfm::ReadModel(tmp / "scene/object/sparse").reconstruction;
  const sfm::Reconstruction estimate = sfm::ReadModel(sparse).reconstruction;
  EXPECT_GE(estimate.images.size(), static_cast<std::size_t>(0.9 * options.num_images));
  const sfm::SimilarityAlignment a = sfm::AlignByCameraCenters(truth, estimate);
  // Camera centres within 1 % of the camera distance, orientations within 1 degree.
  EXPECT_LT(a.rms_center_error, 0.01 * options.camera_distance);
  EXPECT_LT(a.max_rotation_error_deg, 1.0);
  std::cout << "COLMAP registered " << estimate.images.size() << "/" << options.num_images
            << " photos; centre RMS error " << a.rms_center_error / options.camera_distance * 100
            << " % of the camera distance, max rotation error " << a.max_rotation_error_deg
            << " deg\n";
}

}  // namespace
}  // namespace texlume::datasets
