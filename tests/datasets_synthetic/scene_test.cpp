#include "datasets_synthetic/scene.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "datasets_synthetic/object_scene.h"
#include "mesh/mesh.h"
#include "ptm/exr_io.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"
#include "tests/test_util.h"

namespace texlume::datasets {
namespace {

namespace fs = std::filesystem;

// A small scene that still exercises every output (seconds, not minutes).
SceneOptions SmallScene(SceneShape shape, MaterialKind kind) {
  SceneOptions o;
  o.shape = shape;
  o.material.kind = kind;
  o.material.texel_size = 0.004;
  o.material.relief_height = 0.012;
  o.num_images = 6;
  o.image_width = 320;
  o.image_height = 240;
  o.focal_px = 300;
  o.capture_size = 48;
  o.num_capture_lights = 8;
  o.num_held_out_capture_lights = 3;
  o.btf_size = 16;
  o.btf_view_count = 2;
  o.btf_light_count = 2;
  o.num_held_out_views = 1;
  o.held_out_lights_per_view = 2;
  return o;
}

// The small stone sphere at coarse texels, square photos of `side` pixels, no
// BTF or planar surface: for tests of the object's photos and lights alone.
SceneOptions TinySphere(int images, int side, double focal_px) {
  SceneOptions o = SmallScene(SceneShape::kSphere, MaterialKind::kStone);
  o.num_images = images;
  o.write_btf = false;
  o.write_surface = false;
  o.material.texel_size = 0.008;
  o.image_width = o.image_height = side;
  o.focal_px = focal_px;
  return o;
}

// The coarse mesh projected with a COLMAP camera: the object mask it predicts.
cv::Mat ProjectMesh(const mesh::TriangleMesh& mesh, const sfm::Camera& camera,
                    const sfm::Image& image) {
  cv::Mat mask(static_cast<int>(camera.height), static_cast<int>(camera.width), CV_8UC1,
               cv::Scalar(0));
  constexpr int kShift = 8;
  for (std::size_t f = 0; f < mesh.NumFaces(); ++f) {
    std::vector<cv::Point> points;
    for (int k = 0; k < 3; ++k) {
      const auto px = camera.ImageFromCam(image.cam_from_world * mesh.Corner(f, k));
      if (!px) break;
      // OpenCV puts integer coordinates at pixel centres; ours are at corners.
      points.emplace_back(static_cast<int>(std::lround((px->x() - 0.5) * (1 << kShift))),
                          static_cast<int>(std::lround((px->y() - 0.5) * (1 << kShift))));
    }
    if (points.size() == 3) cv::fillConvexPoly(mask, points, cv::Scalar(255), cv::LINE_8, kShift);
  }
  return mask;
}

double IoU(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat i, u;
  cv::bitwise_and(a, b, i);
  cv::bitwise_or(a, b, u);
  return static_cast<double>(cv::countNonZero(i)) / std::max(1, cv::countNonZero(u));
}

void ExpectMasksMatchTheCoarseMesh(const fs::path& object_dir, const std::string& model,
                                   const std::string& masks) {
  const sfm::LoadedModel loaded = sfm::ReadModel(object_dir / model);
  const mesh::LoadedMesh mesh = mesh::LoadMesh(object_dir / "mesh.ply");
  for (const auto& [id, image] : loaded.reconstruction.images) {
    const cv::Mat rendered =
        cv::imread((object_dir / masks / image.name).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(rendered.empty()) << image.name;
    const cv::Mat predicted =
        ProjectMesh(mesh.mesh, loaded.reconstruction.cameras.at(image.camera_id), image);
    EXPECT_GT(IoU(rendered, predicted), 0.97) << object_dir << " " << image.name;
  }
}

class SceneShapesTest : public ::testing::TestWithParam<std::pair<SceneShape, MaterialKind>> {};

TEST_P(SceneShapesTest, MasksOfEveryViewMatchTheCoarseMeshProjectedWithTheColmapCameras) {
  testing::TempDir tmp;
  SceneOptions options = SmallScene(GetParam().first, GetParam().second);
  options.camera_model = GetParam().first == SceneShape::kTorus ? sfm::CameraModelId::kOpenCV
                                                                : sfm::CameraModelId::kPinhole;
  GenerateScene(options, tmp.path());
  ExpectMasksMatchTheCoarseMesh(tmp / "object", "sparse", "masks");
  ExpectMasksMatchTheCoarseMesh(tmp / "object", "held_out/sparse_txt", "held_out/masks");
  // The files agree with each other.
  const sfm::LoadedModel model = sfm::ReadModel(tmp / "object/sparse_txt");
  EXPECT_EQ(model.reconstruction.images.size(), 6u);
  EXPECT_GT(model.reconstruction.points3d.size(), 100u);
  const auto lights = sfm::ReadObjectLightsFile(tmp / "object/lights.json");
  const sfm::LightsModelMatch match =
      sfm::CheckLightsAgainstModel(lights, model.reconstruction, "lights.json");
  EXPECT_TRUE(match.images_without_lights.empty());
  EXPECT_TRUE(match.lights_without_images.empty());
  for (const auto& [name, list] : lights) {
    EXPECT_GE(list.size(), 1u);
    EXPECT_LE(list.size(), 3u);
  }
  EXPECT_EQ(sfm::ReadLpFile(tmp / "material/capture/lights.lp").size(), 8u);
  EXPECT_EQ(sfm::ReadLpFile(tmp / "material/held_out/lights.lp").size(), 3u);
  EXPECT_TRUE(fs::exists(tmp / "material/btf/view_01_light_01.png"));
  // The commands that use the scene name its own paths (they run from its folder).
  const std::string manifest = testing::ReadText(tmp / "MANIFEST.md");
  for (const char* path : {"material/capture/lights.lp", "object/sparse", "object/mesh.ply",
                           "object/held_out/lights.json", "--btf material/btf"}) {
    EXPECT_NE(manifest.find(path), std::string::npos) << path;
    const std::string name = std::string(path).substr(std::string(path).rfind(' ') + 1);
    EXPECT_TRUE(fs::exists(tmp / name)) << name;
  }
  std::vector<std::string> names;
  const auto height = ptm::ReadExr(tmp / "material/ground_truth/height.exr", &names);
  ASSERT_EQ(height.size(), 1u);
  EXPECT_EQ(height[0].cols, 48);
}

INSTANTIATE_TEST_SUITE_P(
    AllShapes, SceneShapesTest,
    ::testing::Values(std::make_pair(SceneShape::kSphere, MaterialKind::kStone),
                      std::make_pair(SceneShape::kCylinder, MaterialKind::kBrick),
                      std::make_pair(SceneShape::kPlane, MaterialKind::kGrooves),
                      std::make_pair(SceneShape::kTorus, MaterialKind::kStone)),
    [](const auto& param_info) { return std::string(SceneShapeName(param_info.param.first)); });

TEST(Scene, FlatLambertianCaptureFollowsTheLpLightsDotTheNormal) {
  testing::TempDir tmp;
  SceneOptions options = SmallScene(SceneShape::kPlane, MaterialKind::kStone);
  options.material.relief_height = 0.0;
  options.write_btf = false;
  options.num_held_out_views = 0;
  GenerateScene(options, tmp.path());
  const auto lights = sfm::ReadLpFile(tmp / "material/capture/lights.lp");
  const double ambient = options.shading.ambient;
  // Per pixel, radiance = albedo * (ambient + l.z): the ratio of two captures
  // cancels the albedo and must equal (ambient + l1.z) / (ambient + l0.z).
  const cv::Mat first =
      Srgb8ToLinear(cv::imread((tmp / "material/capture" / lights[0].filename).string()));
  for (std::size_t k = 1; k < lights.size(); ++k) {
    const cv::Mat other =
        Srgb8ToLinear(cv::imread((tmp / "material/capture" / lights[k].filename).string()));
    const double expected =
        (ambient + lights[k].direction_in_image.z()) / (ambient + lights[0].direction_in_image.z());
    std::vector<double> ratios;
    for (int y = 0; y < first.rows; ++y) {
      for (int x = 0; x < first.cols; ++x) {
        const auto a = first.at<cv::Vec3f>(y, x), b = other.at<cv::Vec3f>(y, x);
        if (a[1] > 0.05f) ratios.push_back(b[1] / a[1]);
      }
    }
    ASSERT_GT(ratios.size(), 1000u);
    std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
    EXPECT_NEAR(ratios[ratios.size() / 2], expected, 0.02 * expected) << lights[k].filename;
  }
}

TEST(Scene, CapturesAgreeWithGroundTruthNormalsInTheLpFrame) {
  testing::TempDir tmp;
  SceneOptions options = SmallScene(SceneShape::kPlane, MaterialKind::kStone);
  options.capture_size = 96;
  options.write_btf = false;
  options.num_held_out_views = 0;
  options.shading.shadows = false;
  GenerateScene(options, tmp.path());
  const auto normals = ptm::ReadExr(tmp / "material/ground_truth/normals.exr");
  const auto albedo = ptm::ReadExr(tmp / "material/ground_truth/albedo.exr");
  const auto lights = sfm::ReadLpFile(tmp / "material/capture/lights.lp");
  // Lambert with the ground-truth normals predicts every capture; a y axis
  // pointing down (image rows) instead of up would predict it badly.
  for (const auto& light : lights) {
    const cv::Mat image =
        Srgb8ToLinear(cv::imread((tmp / "material/capture" / light.filename).string()));
    double sum_sq = 0, sum_sq_flipped = 0;
    int n = 0;
    for (int y = 2; y < image.rows - 2; ++y) {
      for (int x = 2; x < image.cols - 2; ++x) {
        const Eigen::Vector3d nrm(normals[0].at<float>(y, x), normals[1].at<float>(y, x),
                                  normals[2].at<float>(y, x));
        const Eigen::Vector3d& l = light.direction_in_image;
        const Eigen::Vector3d l_flipped(l.x(), -l.y(), l.z());
        const double a = albedo[1].at<float>(y, x);
        const double observed = image.at<cv::Vec3f>(y, x)[1];
        const double predicted = a * (0.02 + std::max(0.0, nrm.dot(l)));
        const double flipped = a * (0.02 + std::max(0.0, nrm.dot(l_flipped)));
        sum_sq += (observed - predicted) * (observed - predicted);
        sum_sq_flipped += (observed - flipped) * (observed - flipped);
        ++n;
      }
    }
    const double rms = std::sqrt(sum_sq / n), rms_flipped = std::sqrt(sum_sq_flipped / n);
    EXPECT_LT(rms, 0.02) << light.filename;
    if (std::abs(light.direction_in_image.y()) > 0.3) {
      EXPECT_GT(rms_flipped, 2 * rms) << light.filename;
    }
  }
}

TEST(Scene, WorldLightsOfObjectPhotosFollowNDotL) {
  // A flat plane object without relief, seen from above: the ratio of two renders
  // under two world lights is (ambient + l1.z) / (ambient + l0.z), normal = +Z.
  MaterialOptions flat;
  flat.relief_height = 0.0;
  const Material material(flat);
  const SurfacePatch plane = ShapePatches(SceneShape::kPlane)[0];
  const BakedMaterial baked(material, plane.u0, plane.u1, plane.v0, plane.v1, false, false, 0.01);
  const Renderer renderer(DisplacePatches({plane}, {&baked}, 0.05), {&baked});
  ObjectSceneOptions o;
  o.shape = SceneShape::kPlane;
  o.num_points = 0;
  o.image_width = 160;
  o.image_height = 120;
  o.focal_px = 150;
  const ObjectScene scene = MakeObjectScene(o);
  const auto& [id, image] = *scene.reconstruction.images.begin();
  const sfm::Camera& camera = scene.reconstruction.cameras.begin()->second;
  const Eigen::Vector3d l0 = Eigen::Vector3d(0.2, 0.1, 0.9).normalized();
  const Eigen::Vector3d l1 = Eigen::Vector3d(-0.6, 0.3, 0.4).normalized();
  const Rendering r0 = renderer.RenderPerspective(camera, image.cam_from_world, {{l0, 1.0}}, {});
  const Rendering r1 = renderer.RenderPerspective(camera, image.cam_from_world, {{l1, 1.0}}, {});
  const double expected = (0.02 + l1.z()) / (0.02 + l0.z());
  int checked = 0;
  for (int y = 0; y < r0.linear_rgb.rows; ++y) {
    for (int x = 0; x < r0.linear_rgb.cols; ++x) {
      if (r0.coverage.at<float>(y, x) < 1.0f) continue;
      const float a = r0.linear_rgb.at<cv::Vec3f>(y, x)[0],
                  b = r1.linear_rgb.at<cv::Vec3f>(y, x)[0];
      ASSERT_NEAR(b / a, expected, 1e-4 * expected);
      ++checked;
    }
  }
  EXPECT_GT(checked, 5000);
}

TEST(Scene, SameSeedSameBytes) {
  testing::TempDir tmp;
  const SceneOptions options = SmallScene(SceneShape::kCylinder, MaterialKind::kGrooves);
  GenerateScene(options, tmp / "a");
  GenerateScene(options, tmp / "b");
  std::size_t compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(tmp / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), tmp / "a");
    std::string a = testing::ReadText(entry.path()), b = testing::ReadText(tmp / "b" / rel);
    if (rel == "scene.json") {  // timings differ between runs; everything else may not
      auto ja = nlohmann::json::parse(a), jb = nlohmann::json::parse(b);
      ja.erase("timings_s");
      jb.erase("timings_s");
      a = ja.dump();
      b = jb.dump();
    }
    EXPECT_TRUE(a == b) << rel << " differs between two runs with the same seed";
    ++compared;
  }
  EXPECT_GT(compared, 40u);
  SceneOptions other = options;
  other.seed = 2;
  other.material.seed = 2;
  GenerateScene(other, tmp / "c");
  EXPECT_NE(testing::ReadText(tmp / "a/material/capture/rti_000.png"),
            testing::ReadText(tmp / "c/material/capture/rti_000.png"));
}

// The sensor changes the object photos only, and scene.json records it.
TEST(Scene, SensorChangesThePhotosOnlyAndIsRecorded) {
  testing::TempDir tmp;
  SceneOptions options = SmallScene(SceneShape::kSphere, MaterialKind::kStone);
  options.num_images = 3;
  options.held_out_lights_per_view = 1;
  options.write_btf = false;
  options.write_surface = false;
  options.material.texel_size = 0.008;
  GenerateScene(options, tmp / "clean");
  options.sensor.read_noise = 0.01;
  options.sensor.white_balance_spread = 0.1;
  GenerateScene(options, tmp / "noisy");
  const auto photo = [&](const char* scene) {
    return cv::imread((tmp / scene / "object/images/image_000.png").string());
  };
  const double rms = cv::norm(photo("clean"), photo("noisy"), cv::NORM_L2) /
                     std::sqrt(3.0 * static_cast<double>(photo("clean").total()));
  EXPECT_GT(rms, 1.0);  // grey levels
  for (const char* same : {"material/capture/rti_000.png", "object/masks/image_000.png"})
    EXPECT_EQ(testing::ReadText(tmp / "clean" / same), testing::ReadText(tmp / "noisy" / same))
        << same;
  const fs::path held = *fs::directory_iterator(tmp / "clean/object/held_out/images");
  EXPECT_EQ(testing::ReadText(held),
            testing::ReadText(tmp / "noisy/object/held_out/images" / held.filename()));
  const nlohmann::json record = nlohmann::json::parse(testing::ReadText(tmp / "noisy/scene.json"));
  EXPECT_EQ(record["sensor"]["read_noise"], 0.01);
  EXPECT_EQ(record["photos"]["image_000.png"]["white_balance"].size(), 3u);
}

// lights.json records each photo light turned by the angle scene.json gives for
// it, of about the stated RMS; the photos themselves are lit as before.
TEST(Scene, LightErrorTurnsTheRecordedLightsByTheRecordedAngles) {
  testing::TempDir tmp;
  SceneOptions options = TinySphere(12, 96, 90);
  options.num_held_out_views = 0;
  GenerateScene(options, tmp / "exact");
  options.light_error_deg = 3.0;
  GenerateScene(options, tmp / "off");
  const auto exact = sfm::ReadObjectLightsFile(tmp / "exact/object/lights.json");
  const auto off = sfm::ReadObjectLightsFile(tmp / "off/object/lights.json");
  const nlohmann::json photos =
      nlohmann::json::parse(testing::ReadText(tmp / "off/scene.json"))["photos"];
  double sum_squares = 0;
  int count = 0;
  for (const auto& [name, lights] : exact) {
    ASSERT_EQ(off.at(name).size(), lights.size());
    EXPECT_EQ(testing::ReadText(tmp / "exact/object/images" / name),
              testing::ReadText(tmp / "off/object/images" / name));
    for (std::size_t k = 0; k < lights.size(); ++k) {
      const double angle_deg =
          std::acos(std::clamp(lights[k].direction_in_world.dot(off.at(name)[k].direction_in_world),
                               -1.0, 1.0)) *
          180.0 / M_PI;
      EXPECT_NEAR(angle_deg, photos[name]["light_error_deg"][k].get<double>(), 1e-3) << name;
      sum_squares += angle_deg * angle_deg;
      ++count;
    }
  }
  ASSERT_GE(count, 12);
  const double rms = std::sqrt(sum_squares / count);
  EXPECT_GT(rms, 1.5);
  EXPECT_LT(rms, 4.5);
}

// A flat, relief-free sample seen from above under one light: what the sheen and
// the interreflection add is known.
class FlatSampleRender : public ::testing::Test {
 protected:
  Rendering Render(const MaterialOptions& material_options, const ShadingOptions& shading,
                   const Eigen::Vector3d& light,
                   const Eigen::Vector3d& view = Eigen::Vector3d::UnitZ()) {
    material_ = std::make_unique<Material>(material_options);
    baked_ = std::make_unique<BakedMaterial>(*material_, -0.1, 0.3, -0.1, 0.3, false, false,
                                             material_options.texel_size);
    const SurfacePatch plane{SurfacePatch::Domain::kRectangle,
                             -0.1,
                             0.3,
                             -0.1,
                             0.3,
                             false,
                             false,
                             [](double u, double v) {
                               return SurfacePoint{{u, v, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
                             }};
    const Renderer renderer(DisplacePatches({plane}, {baked_.get()}, 0.004), {baked_.get()});
    return renderer.RenderOrthographic(48, 48, 0.0, 0.2, 0.004, view, {{light, 1.0}}, shading);
  }
  std::unique_ptr<Material> material_;
  std::unique_ptr<BakedMaterial> baked_;
};

TEST_F(FlatSampleRender, SheenAddsItsGrazingTermExactly) {
  MaterialOptions m;
  m.relief_height = 0.0;
  // Light and viewer low on opposite sides: where sheen is strongest.
  const Eigen::Vector3d l = Eigen::Vector3d(0.9, 0.0, 0.25).normalized();
  const Eigen::Vector3d v = Eigen::Vector3d(-0.9, 0.0, 0.3).normalized();
  const cv::Mat matte = Render(m, {}, l, v).linear_rgb;
  m.sheen = 0.4;
  const cv::Mat sheen = Render(m, {}, l, v).linear_rgb;
  const Eigen::Vector3d half = (l + v).normalized();
  const double expected = 0.4 * std::pow(1.0 - l.dot(half), 5.0) * l.z();
  ASSERT_GT(expected, 0.01);
  const cv::Mat difference = sheen - matte;
  double lo, hi;
  cv::minMaxLoc(difference.reshape(1), &lo, &hi);
  EXPECT_NEAR(lo, expected, 1e-5);
  EXPECT_NEAR(hi, expected, 1e-5);
}

TEST_F(FlatSampleRender, InterreflectionOnlyAddsLightAndNoneOnAFlatSample) {
  MaterialOptions m;
  m.relief_height = 0.0;
  const Eigen::Vector3d l = Eigen::Vector3d(0.3, 0.2, 0.8).normalized();
  ShadingOptions bounce;
  bounce.interreflection_rays = 8;
  EXPECT_EQ(cv::norm(Render(m, {}, l).linear_rgb, Render(m, bounce, l).linear_rgb, cv::NORM_INF),
            0.0);
  m.relief_height = 0.02;  // deep relief: its walls light each other
  const cv::Mat direct = Render(m, {}, l).linear_rgb, both = Render(m, bounce, l).linear_rgb;
  double lo, hi;
  const cv::Mat added = both - direct;
  cv::minMaxLoc(added.reshape(1), &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_GT(cv::mean(both)[1], 1.005 * cv::mean(direct)[1]);
}

TEST(Materials, PeriodicMaterialsAreSeamlessAndBakingIsFaithful) {
  for (auto kind : {MaterialKind::kStone, MaterialKind::kBrick, MaterialKind::kGrooves}) {
    MaterialOptions o;
    o.kind = kind;
    const double period_u = 2.3, period_v = 1.7;
    const Material m(o, period_u, period_v);
    for (double u : {0.013, 0.5, 1.91}) {
      for (double v : {0.021, 0.77}) {
        EXPECT_NEAR(m.Height(u, v), m.Height(u + period_u, v), 1e-9) << MaterialKindName(kind);
        EXPECT_NEAR(m.Height(u, v), m.Height(u, v + period_v), 1e-9) << MaterialKindName(kind);
        EXPECT_TRUE(m.Albedo(u, v).isApprox(m.Albedo(u + period_u, v + period_v), 1e-9));
        EXPECT_LE(std::abs(m.Height(u, v)), o.relief_height / 2 + 1e-12);
      }
    }
    // Baked at the texel size, heights agree with the procedural ones at texel centres.
    const BakedMaterial baked(m, 0, period_u, 0, period_v, true, true, o.texel_size);
    const double t = period_u / std::lround(period_u / o.texel_size);
    const double tv = period_v / std::lround(period_v / o.texel_size);
    EXPECT_NEAR(baked.Height(10.5 * t, 20.5 * tv), m.Height(10.5 * t, 20.5 * tv), 1e-7);
    EXPECT_NEAR(baked.Height(-0.5 * t, 0.5 * tv), m.Height(period_u - 0.5 * t, 0.5 * tv), 1e-7);
  }
}

TEST(Materials, KindsDifferInStructure) {
  // Grooves run along v: height varies much more across u than along v.
  MaterialOptions o;
  o.kind = MaterialKind::kGrooves;
  const Material grooves(o);
  double along_u = 0, along_v = 0;
  for (int i = 0; i < 400; ++i) {
    const double s = i * 0.0013;
    along_u += std::abs(grooves.HeightGradient(s, 0.3).x());
    along_v += std::abs(grooves.HeightGradient(0.3, s).y());
  }
  EXPECT_GT(along_u, 3 * along_v);
  EXPECT_EQ(MaterialKindFromName("brick"), MaterialKind::kBrick);
  EXPECT_FALSE(MaterialKindFromName("marble").has_value());
  o.texel_size = 0;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

TEST(DomeLights, CountsElevationsAndInterleaving) {
  const auto dome = DomeLights(40, 15, 80, 0.0);
  const auto held = DomeLights(10, 20, 75, 0.5);
  ASSERT_EQ(dome.size(), 40u);
  ASSERT_EQ(held.size(), 10u);
  for (const auto& l : dome) {
    EXPECT_NEAR(l.norm(), 1.0, 1e-12);
    const double elevation = std::asin(l.z()) * 180 / M_PI;
    EXPECT_GE(elevation, 15 - 1e-9);
    EXPECT_LE(elevation, 80 + 1e-9);
  }
  for (const auto& h : held) {
    for (const auto& l : dome) EXPECT_GT((h - l).norm(), 0.05);
  }
}

TEST(SceneOptions, BadSettingsAreRefused) {
  SceneOptions o;
  o.num_images = 1;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.camera_model = sfm::CameraModelId::kFov;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.material.relief_height = -1;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.held_out_min_elevation_deg = 40;
  o.held_out_max_elevation_deg = 30;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.light_error_deg = 25;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

// Held-out lights can be grazing: every one lies between the elevations asked.
TEST(Scene, HeldOutLightsLieBetweenTheElevationsAsked) {
  testing::TempDir tmp;
  SceneOptions options = TinySphere(3, 64, 60);
  options.num_held_out_views = 2;
  options.held_out_lights_per_view = 4;
  options.held_out_min_elevation_deg = 5;
  options.held_out_max_elevation_deg = 12;
  GenerateScene(options, tmp.path());
  const auto lights = sfm::ReadObjectLightsFile(tmp / "object/held_out/lights.json");
  ASSERT_EQ(lights.size(), 8u);
  for (const auto& [name, list] : lights) {
    const double elevation_deg = std::asin(list.at(0).direction_in_world.z()) * 180.0 / M_PI;
    EXPECT_GE(elevation_deg, 5.0 - 1e-6) << name;
    EXPECT_LE(elevation_deg, 12.0 + 1e-6) << name;
  }
}

TEST(ShadingOptions, OutOfRangeSettingsAreRefused) {
  ShadingOptions o;
  EXPECT_NO_THROW(o.Check());
  o.ambient = 1.5;
  EXPECT_THROW(o.Check(), OptionError);
  o.ambient = 0.1;
  o.exposure = 0.0;
  EXPECT_THROW(o.Check(), OptionError);
  o.exposure = 1.0;
  o.samples_per_axis = 9;
  EXPECT_THROW(o.Check(), OptionError);
}

TEST(PlanarSurfaceOptions, ScaleMustDivideTheSizeAndNestedSettingsBeValid) {
  PlanarSurfaceOptions o;
  EXPECT_NO_THROW(o.Check());
  o.scale = 3;  // 256 is not a multiple of 3
  EXPECT_THROW(o.Check(), OptionError);
  o.scale = 2;
  o.offset = -1;
  EXPECT_THROW(o.Check(), OptionError);
  o.offset = 0;
  o.shading.samples_per_axis = 0;
  EXPECT_THROW(o.Check(), OptionError);
  EXPECT_THROW(RenderPlanarSurface(o, {}, {}), OptionError);
}

}  // namespace
}  // namespace texlume::datasets
