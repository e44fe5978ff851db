#include "ptm/sphere_lights.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "datasets_synthetic/renderer.h"
#include "datasets_synthetic/scene.h"
#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

TEST(SphereLights, RenderedGlossySpheresGiveTheirLightsWithinTwoDegrees) {
  testing::TempDir tmp;
  // A near-black glossy sphere of radius 1 on a stone floor, seen straight down.
  datasets::MaterialOptions glossy;
  glossy.relief_height = 0;
  glossy.albedo_scale = 0.05;
  glossy.specular = 1.0;
  glossy.shininess = 2000;
  datasets::MaterialOptions floor_material;
  floor_material.relief_height = 0;
  const datasets::Material sphere_m(glossy, 2 * M_PI, 0), floor_m(floor_material);
  auto patches = datasets::ShapePatches(datasets::SceneShape::kSphere);
  const auto& sp = patches[0];
  datasets::SurfacePatch floor = datasets::ShapePatches(datasets::SceneShape::kPlane)[0];
  floor.u0 = floor.v0 = -3;
  floor.u1 = floor.v1 = 3;
  const datasets::BakedMaterial sphere_baked(sphere_m, sp.u0, sp.u1, sp.v0, sp.v1, true, false,
                                             0.01);
  const datasets::BakedMaterial floor_baked(floor_m, -3, 3, -3, 3, false, false, 0.01);
  const datasets::Renderer renderer(
      datasets::DisplacePatches({sp, floor}, {&sphere_baked, &floor_baked}, 0.01),
      {&sphere_baked, &floor_baked});
  const int size = 200;
  const double texel = 3.0 / size;  // the image covers [-1.5, 1.5]^2
  const auto lights = datasets::DomeLights(12, 25, 75, 0.0);
  std::vector<std::filesystem::path> files;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const datasets::Rendering r = renderer.RenderOrthographic(
        size, size, -1.5, 1.5, texel, Eigen::Vector3d::UnitZ(), {{lights[i], 1.0}}, {});
    files.push_back(tmp / ("sphere_" + std::to_string(i) + ".png"));
    datasets::WritePngAtomically(files.back(), datasets::LinearToSrgb8(r.linear_rgb));
  }
  const SphereCircle truth{100.0, 100.0, 1.0 / texel};
  for (const bool detect : {false, true}) {
    std::vector<std::string> skipped;
    SphereCircle used;
    const auto entries =
        LightsFromSphere(files, detect ? std::nullopt : std::optional(truth), {}, &skipped, &used);
    ASSERT_EQ(entries.size(), lights.size());
    if (detect) {
      EXPECT_NEAR(used.center_x, truth.center_x, 2.0);
      EXPECT_NEAR(used.center_y, truth.center_y, 2.0);
      EXPECT_NEAR(used.radius, truth.radius, 2.5);
    }
    for (std::size_t i = 0; i < lights.size(); ++i) {
      const double error_deg =
          std::acos(std::clamp(entries[i].direction_in_image.dot(lights[i]), -1.0, 1.0)) * 180 /
          M_PI;
      EXPECT_LT(error_deg, 2.0) << entries[i].filename << (detect ? " (detected circle)" : "");
    }
  }
}

TEST(SphereLights, MirrorGeometryKnownAnswers) {
  const SphereCircle c{50, 50, 10};
  // Highlight at the centre: light along the viewer.
  EXPECT_TRUE(LightFromHighlight(c, {50, 50}).isApprox(Eigen::Vector3d::UnitZ()));
  // Normal at 45 degrees towards +x (right): light at 90 degrees, along +x.
  const double off = 10 * std::sqrt(0.5);
  EXPECT_TRUE(LightFromHighlight(c, {50 + off, 50}).isApprox(Eigen::Vector3d::UnitX(), 1e-9));
  // Up in the image is +y in the light frame.
  EXPECT_GT(LightFromHighlight(c, {50, 45}).y(), 0.5);
}

TEST(HighlightOptions, OutOfRangeFractionsAreRefused) {
  HighlightOptions o;
  EXPECT_NO_THROW(o.Check());
  o.threshold_fraction = 0.0;
  EXPECT_THROW(o.Check(), OptionError);
  o.threshold_fraction = 0.9;
  o.search_radius_fraction = 1.5;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(LightsFromSphere({}, std::nullopt, o), OptionError);
}

}  // namespace
}  // namespace texlume::ptm
