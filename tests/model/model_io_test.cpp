#include "model/model_io.h"

#include <gtest/gtest.h>

#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"
#include "model/web_model.h"
#include "tests/test_util.h"

namespace texlume::model {
namespace {

TEST(LightResponseJson, RoundTripsAndRefusesMalformedRecordsNamingTheFile) {
  ptm::LightResponse r;
  for (std::size_t k = 0; k < r.elevation_factor.size(); ++k)
    r.elevation_factor[k] = 0.7 + 0.05 * static_cast<double>(k);
  r.ambient = 0.021;
  r.oren_nayar_b_over_a = 0.13;
  const nlohmann::json record = LightResponseJson(r);
  EXPECT_EQ(record["elevations_deg"][3].get<double>(), 30.0);
  const ptm::LightResponse back = LightResponseFromJson(record, "m/manifest.json");
  EXPECT_EQ(back.elevation_factor, r.elevation_factor);
  EXPECT_EQ(back.ambient, r.ambient);
  EXPECT_EQ(back.oren_nayar_b_over_a, r.oren_nayar_b_over_a);
  nlohmann::json older = record;  // written before the view term: none
  older.erase("oren_nayar_b_over_a");
  EXPECT_EQ(LightResponseFromJson(older, "m/manifest.json").oren_nayar_b_over_a, 0.0);

  nlohmann::json short_factors = record;
  short_factors["factors"].erase(0);
  nlohmann::json negative = record;
  negative["factors"][2] = -1.0;
  nlohmann::json moved_knot = record;
  moved_knot["elevations_deg"][1] = 12.0;
  nlohmann::json no_ambient = record;
  no_ambient.erase("ambient");
  nlohmann::json view_term_text = record, view_term_large = record;
  view_term_text["oren_nayar_b_over_a"] = "0.1";
  view_term_large["oren_nayar_b_over_a"] = 3.0;
  for (const nlohmann::json& bad : {short_factors, negative, moved_knot, no_ambient, view_term_text,
                                    view_term_large, nlohmann::json(), nlohmann::json::array()}) {
    try {
      LightResponseFromJson(bad, "m/manifest.json");
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("m/manifest.json"), std::string::npos) << e.what();
    }
  }
}

// One triangle on a 16 x 16 LRGB atlas whose relief's horizon is 45 degrees in
// every sector.
TexturedModel ShadowedTriangle() {
  TexturedModel model;
  model.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  model.mesh.faces = {{0, 1, 2}};
  model.corner_px = {{Eigen::Vector2f(2, 14), Eigen::Vector2f(14, 14), Eigen::Vector2f(2, 2)}};
  model.face_atlas = {0};
  ptm::Ptm& atlas = model.atlases.emplace_back();
  atlas.Resize(ptm::PtmFormat::kLrgb, 16, 16);
  for (std::size_t t = 0; t < atlas.NumTexels(); ++t) {
    atlas.Coefficients(t)[5] = 0.6f;
    for (std::size_t c = 0; c < 3; ++c) atlas.colour[t * 3 + c] = c == 0 ? 1.0f : 0.8f;
  }
  ptm::SelfShadowing& shadowing = model.shadowing.emplace_back();
  shadowing.horizon.width = shadowing.horizon.height = 16;
  shadowing.horizon.sectors = 8;
  shadowing.horizon.elevation_rad.assign(16 * 16 * 8, static_cast<float>(std::numbers::pi / 4));
  shadowing.height_scale = 1.5;
  shadowing.shadow_floor = 0.3;
  shadowing.penumbra_rad = 0.07;
  return model;
}

TEST(ModelFolder, TheReliefsHorizonRoundTripsAndReachesTheWebModel) {
  testing::TempDir dir;
  const TexturedModel model = ShadowedTriangle();
  WriteModelFolder(dir.path() / "m", model, nlohmann::json::object());
  const nlohmann::json manifest = ReadModelManifest(dir.path() / "m");
  EXPECT_EQ(manifest["atlases"][0]["horizon"], "horizon_atlas_0.exr");
  EXPECT_TRUE(manifest["ptm_evaluation"].contains("self_shadowing"));
  const TexturedModel back = ReadModelFolder(dir.path() / "m");
  ASSERT_EQ(back.shadowing.size(), 1u);
  EXPECT_EQ(back.shadowing[0].horizon.elevation_rad, model.shadowing[0].horizon.elevation_rad);
  EXPECT_FLOAT_EQ(static_cast<float>(back.shadowing[0].shadow_floor), 0.3f);

  // The web model: 16 sectors in 4 RGBA PNGs, 45 degrees = byte 128 of pi / 2.
  const WebModel web = BuildWebModel(dir.path() / "m");
  const nlohmann::json& horizon = web.scene["atlases"][0]["horizon"];
  ASSERT_EQ(horizon["files"].size(), 4u);
  EXPECT_EQ(horizon["sectors"], 16);
  EXPECT_NEAR(horizon["shadow_floor"].get<double>(), 0.3, 1e-6);
  const std::vector<unsigned char>& png = web.files.at(horizon["files"][3].get<std::string>());
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(image.type(), CV_8UC4);
  EXPECT_EQ(image.at<cv::Vec4b>(5, 7), cv::Vec4b(128, 128, 128, 128));

  // A horizon map of another size than its atlas is refused, naming the file.
  ptm::SelfShadowing small = model.shadowing[0];
  small.horizon.width = small.horizon.height = 8;
  small.horizon.elevation_rad.resize(8 * 8 * 8);
  ptm::WriteSelfShadowingExr(small, dir.path() / "m/horizon_atlas_0.exr");
  try {
    ReadModelFolder(dir.path() / "m");
    ADD_FAILURE() << "accepted a horizon map of another size";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("horizon_atlas_0.exr"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace texlume::model
