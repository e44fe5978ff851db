// The model folder's exports as other tools read them: the GLB stands in glTF's
// frame, carries tangents, an albedo, a normal map and the PTM planes; the OBJ has
// vertex normals and reads back.
#include "model/glb_writer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "core/file_util.h"
#include "ptm/ptm_io.h"
#include "tests/test_util.h"

namespace texlume::model {
namespace {

namespace fs = std::filesystem;

// A tilted square of two faces on a 32 x 32 atlas whose PTM leans toward +u, in a
// frame whose up is +Z and whose photos were taken from +X.
TexturedModel TiltedSquare() {
  TexturedModel m;
  m.mesh.vertices = {{0, 0, 1}, {0, 1, 1}, {0, 1, 2}, {0, 0, 2}};
  m.mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  m.corner_px = {{Eigen::Vector2f(1, 31), Eigen::Vector2f(31, 31), Eigen::Vector2f(31, 1)},
                 {Eigen::Vector2f(1, 31), Eigen::Vector2f(31, 1), Eigen::Vector2f(1, 1)}};
  m.face_atlas = {0, 0};
  ptm::Ptm atlas;
  atlas.Resize(ptm::PtmFormat::kLrgb, 32, 32);
  for (std::size_t t = 0; t < atlas.NumTexels(); ++t) {
    const float a[6] = {-0.3f, -0.3f, 0.0f, 0.2f, 0.0f, 0.6f};  // maximum at lu = 1/3
    std::memcpy(atlas.Coefficients(t), a, sizeof a);
    for (int c = 0; c < 3; ++c) atlas.colour[t * 3 + static_cast<std::size_t>(c)] = 0.5f + 0.1f * c;
  }
  m.atlases = {atlas};
  m.orientation.up = Eigen::Vector3d::UnitZ();
  m.orientation.front = Eigen::Vector3d::UnitX();
  return m;
}

struct Glb {
  nlohmann::json json;
  std::string bin;
  std::string View(int view) const {
    const nlohmann::json& v = json["bufferViews"][static_cast<std::size_t>(view)];
    return bin.substr(v["byteOffset"].get<std::size_t>(), v["byteLength"].get<std::size_t>());
  }
  template <typename T>
  std::vector<T> Accessor(int accessor) const {
    const nlohmann::json& a = json["accessors"][static_cast<std::size_t>(accessor)];
    const std::string bytes = View(a["bufferView"].get<int>());
    std::vector<T> out(bytes.size() / sizeof(T));
    std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
    return out;
  }
  cv::Mat Texture(int texture, int flags = cv::IMREAD_COLOR) const {
    const int image = json["textures"][static_cast<std::size_t>(texture)]["source"].get<int>();
    const std::string png = View(json["images"][static_cast<std::size_t>(image)]["bufferView"]);
    return cv::imdecode(std::vector<unsigned char>(png.begin(), png.end()), flags);
  }
};

Glb ReadGlb(const fs::path& path) {
  const std::string bytes = ReadFileBytes(path, 1u << 30);
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  EXPECT_EQ(u32(0), 0x46546C67u);
  EXPECT_EQ(u32(8), bytes.size());
  const std::uint32_t json_length = u32(12);
  Glb glb;
  glb.json = nlohmann::json::parse(bytes.substr(20, json_length));
  glb.bin = bytes.substr(20 + json_length + 8, u32(20 + json_length));
  return glb;
}

Eigen::Matrix4d NodeMatrix(const Glb& glb) {
  Eigen::Matrix4d m;
  const nlohmann::json& values = glb.json["nodes"][0]["matrix"];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m(r, c) = values[static_cast<std::size_t>(4 * c + r)].get<double>();
  return m;
}

class ModelExports : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteModelFolder(tmp_ / "model", model_, nlohmann::json::object());
    glb_ = ReadGlb(tmp_ / "model/model.glb");
  }
  testing::TempDir tmp_;
  TexturedModel model_ = TiltedSquare();
  Glb glb_;
};

TEST_F(ModelExports, TheGlbStandsUpOnTheGroundFacingThePhotos) {
  const Eigen::Matrix4d m = NodeMatrix(glb_);
  const Eigen::Matrix3d rotation = m.block(0, 0, 3, 3);
  EXPECT_TRUE(m.isApprox(GltfFromModel(model_)));
  // Up (+Z here) becomes glTF's +Y, the photos' side (+X) glTF's +Z.
  EXPECT_TRUE((rotation * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE((rotation * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(rotation.determinant(), 1.0, 1e-12);
  // The lowest point (z = 1) sits at Y = 0, the centre on the Y axis.
  const Eigen::Vector4d low = m * Eigen::Vector4d(0, 0.5, 1, 1);
  EXPECT_NEAR(low.y(), 0.0, 1e-12);
  EXPECT_NEAR(low.x(), 0.0, 1e-12);
  EXPECT_NEAR(low.z(), 0.0, 1e-12);
  // The extras give the inverse, for the way back to COLMAP's frame.
  Eigen::Matrix4d back;
  const nlohmann::json& values =
      glb_.json["nodes"][0]["extras"]["texlume_frame"]["colmap_from_gltf"];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      back(r, c) = values[static_cast<std::size_t>(4 * c + r)].get<double>();
  EXPECT_TRUE((back * m).isApprox(Eigen::Matrix4d::Identity(), 1e-12));
}

TEST_F(ModelExports, TheGlbHasUnitTangentsAlongTheAtlasFrameAndANormalMapOfThePtmNormals) {
  const nlohmann::json& primitive = glb_.json["meshes"][0]["primitives"][0];
  const std::vector<float> tangents = glb_.Accessor<float>(primitive["attributes"]["TANGENT"]);
  ASSERT_EQ(tangents.size(), 6u * 4);
  for (std::size_t corner = 0; corner < 6; ++corner) {
    const Eigen::Vector3d t(tangents[corner * 4], tangents[corner * 4 + 1],
                            tangents[corner * 4 + 2]);
    EXPECT_NEAR(t.norm(), 1.0, 1e-6);
    EXPECT_EQ(std::abs(tangents[corner * 4 + 3]), 1.0f);
    // The atlas's u runs along the model's +Y on this square.
    EXPECT_TRUE(t.isApprox(Eigen::Vector3d::UnitY(), 1e-5)) << t.transpose();
  }
  const nlohmann::json& material = glb_.json["materials"][0];
  const cv::Mat normal = glb_.Texture(material["normalTexture"]["index"]);
  // PtmNormal: the maximum at lu = 0.2 / 0.6 = 1/3, so n = (1/3, 0, sqrt(8/9)).
  const cv::Vec3b n = normal.at<cv::Vec3b>(16, 16);  // BGR
  EXPECT_NEAR(n[2], 127.5 * (1.0 + 1.0 / 3.0), 1.0);
  EXPECT_NEAR(n[1], 127.5, 1.0);
  EXPECT_NEAR(n[0], 127.5 * (1.0 + std::sqrt(8.0 / 9.0)), 1.0);
  EXPECT_TRUE(material["pbrMetallicRoughness"].contains("baseColorTexture"));
}

TEST_F(ModelExports, TheGlbCarriesThePtmPlanesThatDequantiseToTheAtlas) {
  const nlohmann::json& ptm = glb_.json["materials"][0]["extensions"][kGltfPtmExtension];
  EXPECT_EQ(glb_.json["extensionsUsed"][0], kGltfPtmExtension);
  EXPECT_FALSE(glb_.json.contains("extensionsRequired"));  // plain viewers show colour and relief
  ASSERT_EQ(ptm["planes"].size(), 3u);                     // LRGB: colour, then 6 coefficients
  EXPECT_EQ(ptm["colorspace"], "lrgb");
  const std::vector<float> scale = ptm["materials"][0]["scale"], bias = ptm["materials"][0]["bias"];
  // Plane 3 is the constant coefficient a5 (web order 1, u, v, ...), plane 4 is a3 (u).
  const cv::Mat second = glb_.Texture(ptm["planes"][1]["index"]);
  auto value = [&](int plane, std::uint8_t byte) {
    return (byte / 255.0 - bias[static_cast<std::size_t>(plane)]) *
           scale[static_cast<std::size_t>(plane)];
  };
  const cv::Vec3b px = second.at<cv::Vec3b>(5, 7);
  EXPECT_NEAR(value(3, px[2]), 0.6, 2e-3);
  EXPECT_NEAR(value(4, px[1]), 0.2, 2e-3);
  EXPECT_NEAR(ptm["evaluation"]["horizon_elevation_deg"].get<double>(), ptm::kHorizonElevationDeg,
              0);
}

TEST_F(ModelExports, TheGlbHasNoHorizonWhenTheModelCastsNoShadows) {
  EXPECT_FALSE(glb_.json["materials"][0]["extensions"][kGltfPtmExtension].contains("horizon"));
}

TEST(ModelExport, TheGlbCarriesTheReliefsHorizonAtSixteenAzimuths) {
  TexturedModel model = TiltedSquare();
  ptm::SelfShadowing& shadowing = model.shadowing.emplace_back();
  ptm::HorizonMap& h = shadowing.horizon;
  h.width = h.height = 32;
  h.sectors = 8;  // the GLB's 16 azimuths read between them
  h.elevation_rad.resize(h.NumTexels() * 8);
  for (std::size_t t = 0; t < h.NumTexels(); ++t)
    for (std::size_t s = 0; s < 8; ++s)
      h.elevation_rad[t * 8 + s] = static_cast<float>(0.1 * s + 0.02 * static_cast<double>(t % 9));
  shadowing.shadow_floor = 0.25;
  shadowing.penumbra_rad = 0.07;
  testing::TempDir tmp;
  WriteModelFolder(tmp / "model", model, nlohmann::json::object());
  const Glb glb = ReadGlb(tmp / "model/model.glb");
  const nlohmann::json& ptm = glb.json["materials"][0]["extensions"][kGltfPtmExtension];
  ASSERT_TRUE(ptm.contains("horizon"));
  const nlohmann::json& horizon = ptm["horizon"];
  ASSERT_EQ(horizon["sectors"].get<int>(), 16);
  ASSERT_EQ(horizon["textures"].size(), 4u);
  EXPECT_EQ(horizon["shadow_floor"].get<double>(), 0.25);
  EXPECT_EQ(horizon["penumbra_rad"].get<double>(), 0.07);
  const double scale = horizon["elevation_scale"].get<double>();
  EXPECT_NEAR(scale, std::numbers::pi / 2, 1e-12);
  // Sector s is channel s % 4 (R, G, B, A) of texture s / 4; OpenCV decodes BGRA.
  const int bgra[4] = {2, 1, 0, 3};
  for (int s = 0; s < 16; ++s) {
    const cv::Mat png = glb.Texture(horizon["textures"][static_cast<std::size_t>(s / 4)]["index"],
                                    cv::IMREAD_UNCHANGED);
    ASSERT_EQ(png.type(), CV_8UC4);
    ASSERT_EQ(png.size(), cv::Size(32, 32));
    for (const std::size_t t : {std::size_t{0}, std::size_t{37}, std::size_t{1000}}) {
      const cv::Vec4b px = png.at<cv::Vec4b>(static_cast<int>(t / 32), static_cast<int>(t % 32));
      EXPECT_NEAR(px[bgra[s % 4]] / 255.0 * scale, h.ElevationAt(t, 2 * std::numbers::pi * s / 16),
                  0.5 / 255.0 * scale + 1e-9)
          << "sector " << s << ", texel " << t;
    }
  }
}

TEST_F(ModelExports, TheObjHasVertexNormalsAndReadsBack) {
  const std::string obj = testing::ReadText(tmp_ / "model/model.obj");
  EXPECT_NE(obj.find("\nvn 1.000000 0.000000 0.000000\n"), std::string::npos) << obj;
  EXPECT_NE(obj.find("\nf 1/1/1 2/2/2 3/3/3\n"), std::string::npos) << obj;
  const std::string mtl = testing::ReadText(tmp_ / "model/model.mtl");
  EXPECT_NE(mtl.find("\nnorm normal_0.png\nmap_Bump normal_0.png\n"), std::string::npos) << mtl;
  const TexturedModel back = ReadModelFolder(tmp_ / "model");
  EXPECT_EQ(back.mesh.faces, model_.mesh.faces);
  EXPECT_TRUE(back.orientation.up.isApprox(model_.orientation.up));
  EXPECT_TRUE(back.orientation.front.isApprox(model_.orientation.front));
}

}  // namespace
}  // namespace texlume::model
