#include "sfm/lights.h"

#include <gtest/gtest.h>

#include <sstream>

#include "core/errors.h"
#include "tests/test_util.h"

namespace texlume::sfm {
namespace {

TEST(Lp, RoundTripIsExactAndMatchesByName) {
  std::vector<LpEntry> entries = {
      {"C:\\capture\\img_01.jpg", Eigen::Vector3d(0.3, -0.2, 0.5).normalized()},
      {"img 02.jpg", Eigen::Vector3d(-0.1, 0.7, 0.4).normalized()},
      {"sub/img_03.jpg", Eigen::Vector3d(0, 0, 1)}};
  std::stringstream s;
  WriteLp(entries, s);
  const auto back = ReadLp(s, "lights.lp");
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back[i].filename, entries[i].filename);
    EXPECT_EQ(back[i].direction_in_image, entries[i].direction_in_image);
  }
  // Matching is by file name, whatever folder either side names.
  EXPECT_EQ(FindLpEntry(back, "photos/img_01.jpg"), &back[0]);
  EXPECT_EQ(FindLpEntry(back, "img 02.jpg"), &back[1]);
  EXPECT_EQ(FindLpEntry(back, "img_04.jpg"), nullptr);
}

TEST(Lp, ReadsWindowsLineEndingsAndNormalises) {
  std::istringstream in("2\r\na.jpg 0 0 2\r\nb.jpg 3 0 4\r\n\r\n");
  const auto e = ReadLp(in, "x.lp");
  EXPECT_TRUE(e[0].direction_in_image.isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(e[1].direction_in_image.isApprox(Eigen::Vector3d(0.6, 0, 0.8)));
}

TEST(LpBadInput, ErrorsNameFileAndLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty file"},
      {"x\n", "x.lp:1:"},
      {"2\na.jpg 0 0 1\n", "lists 1"},
      {"1\na.jpg 0 0\n", "x.lp:2:"},
      {"1\na.jpg 0 zero 1\n", "x.lp:2:"},
      {"1\na.jpg 0 0 0\n", "zero"},
      {"1\na.jpg 0 0 1\nb.jpg 0 0 1\n", "x.lp:3:"},
      {"2\na.jpg 0 0 1\ndir/a.jpg 0 0 1\n", "listed twice"}};
  for (const auto& [text, expected] : cases) {
    std::istringstream in(text);
    const std::string error = testing::InputErrorMessage([&] { ReadLp(in, "x.lp"); });
    EXPECT_NE(error.find(expected), std::string::npos) << "'" << text << "' gave '" << error << "'";
  }
}

TEST(ObjectLights, RoundTripWithDirectionalAndPointLights) {
  ObjectLights lights;
  ObjectLight d;
  d.direction_in_world = Eigen::Vector3d(1, 2, 3).normalized();
  d.intensity = 0.8;
  ObjectLight p;
  p.kind = ObjectLight::Kind::kPoint;
  p.position_in_world = {4, 5, 6};
  lights["a.png"] = {d};
  lights["b.png"] = {d, p};
  std::stringstream s;
  WriteObjectLights(lights, s);
  const ObjectLights back = ReadObjectLights(s, "lights.json");
  ASSERT_EQ(back.size(), 2u);
  ASSERT_EQ(back.at("b.png").size(), 2u);
  EXPECT_TRUE(back.at("a.png")[0].direction_in_world.isApprox(d.direction_in_world, 1e-15));
  EXPECT_EQ(back.at("a.png")[0].intensity, 0.8);
  EXPECT_EQ(back.at("b.png")[1].kind, ObjectLight::Kind::kPoint);
  EXPECT_TRUE(back.at("b.png")[1].DirectionFrom({4, 5, 0}).isApprox(Eigen::Vector3d(0, 0, 1)));
}

TEST(ObjectLights, SingleObjectEntriesAndInferredTypes) {
  std::istringstream in(R"({"images": {"a.png": {"direction": [0, 0, 2]},
                                       "b.png": {"position": [1, 1, 1], "intensity": 2}}})");
  const ObjectLights l = ReadObjectLights(in, "l.json");
  EXPECT_TRUE(l.at("a.png")[0].direction_in_world.isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_EQ(l.at("b.png")[0].kind, ObjectLight::Kind::kPoint);
  EXPECT_EQ(l.at("b.png")[0].intensity, 2.0);
}

TEST(ObjectLightsBadInput, ErrorsNameTheFileAndTheImage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{\n\"images\": {\n\"a.png\": [1, 2,\n}", "l.json:4:"},
      {"[]", "'images'"},
      {R"({"images": {"a.png": {"direction": [0, 0]}}})", "'a.png'"},
      {R"({"images": {"a.png": {"direction": [0, 0, 0]}}})", "zero"},
      {R"({"images": {"a.png": {"type": "spot", "direction": [0, 0, 1]}}})", "unknown type"},
      {R"({"images": {"a.png": {"direction": [0, 0, 1], "intensity": -1}}})", "positive"},
      {R"({"images": {"a.png": []}})", "empty"},
      {R"({"frame": "camera", "images": {}})", "frame"}};
  for (const auto& [text, expected] : cases) {
    std::istringstream in(text);
    const std::string error = testing::InputErrorMessage([&] { ReadObjectLights(in, "l.json"); });
    EXPECT_EQ(error.rfind("l.json", 0), 0u) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << "'" << text << "' gave '" << error << "'";
  }
}

TEST(ObjectLightsBadInput, LightsForUnregisteredImagesAreListedAndAllUnknownRefused) {
  Reconstruction r;
  Image image;
  image.image_id = ImageId(1);
  image.name = "a.png";
  r.images[image.image_id] = image;
  image.image_id = ImageId(2);
  image.name = "b.png";
  r.images[image.image_id] = image;
  ObjectLights lights;
  lights["a.png"] = {ObjectLight{}};
  EXPECT_EQ(CheckLightsAgainstModel(lights, r, "l.json").images_without_lights,
            std::vector<std::string>{"b.png"});
  // A photo SfM did not register: listed, not refused.
  lights["zzz.png"] = {ObjectLight{}};
  const LightsModelMatch match = CheckLightsAgainstModel(lights, r, "l.json");
  EXPECT_EQ(match.lights_without_images, std::vector<std::string>{"zzz.png"});
  EXPECT_EQ(match.images_without_lights, std::vector<std::string>{"b.png"});
  // A file for other photos altogether: refused, naming one.
  ObjectLights other;
  other["zzz.png"] = {ObjectLight{}};
  const std::string error =
      testing::InputErrorMessage([&] { CheckLightsAgainstModel(other, r, "l.json"); });
  EXPECT_NE(error.find("zzz.png"), std::string::npos) << error;
  EXPECT_NE(error.find("l.json"), std::string::npos) << error;
}

}  // namespace
}  // namespace texlume::sfm
