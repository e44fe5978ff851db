#include "render/model_render.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>

#include "core/srgb.h"
#include "ptm/light_response.h"

namespace texlume::render {
namespace {

// The square's frame in the world: tilted, so that a renderer that shaded with
// world directions instead of the face frame's would not pass.
const Eigen::Matrix3d kWorldFromSquare = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()) *
                                          Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitY()))
                                             .toRotationMatrix();

// A square in its frame's plane z = 0, facing +z, textured with one PTM atlas
// whose luminance is the same under every light: what the render shows then is
// the light response alone.
model::TexturedModel FlatSquare() {
  model::TexturedModel m;
  for (const Eigen::Vector3d& corner : {Eigen::Vector3d(-1, -1, 0), Eigen::Vector3d(1, -1, 0),
                                        Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(-1, 1, 0)})
    m.mesh.vertices.push_back(kWorldFromSquare * corner);
  m.mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  m.corner_px = {{Eigen::Vector2f(1, 31), Eigen::Vector2f(31, 31), Eigen::Vector2f(31, 1)},
                 {Eigen::Vector2f(1, 31), Eigen::Vector2f(31, 1), Eigen::Vector2f(1, 1)}};
  m.face_atlas = {0, 0};
  ptm::Ptm atlas;
  atlas.Resize(ptm::PtmFormat::kLrgb, 32, 32);
  for (std::size_t t = 0; t < atlas.NumTexels(); ++t) {
    const float a[6] = {0, 0, 0, 0, 0, 0.6f};  // L = 0.6 under any light
    std::memcpy(atlas.Coefficients(t), a, sizeof a);
    for (int c = 0; c < 3; ++c) atlas.colour[t * 3 + static_cast<std::size_t>(c)] = 1.0f;
  }
  m.atlases = {atlas};
  return m;
}

// A 64 x 64 pinhole camera at (0, -2, 2) in the square's frame, looking at its
// centre, 45 degrees from its normal.
struct ObliqueCamera {
  sfm::Camera camera;
  sfm::Rigid3d cam_from_world;
  Eigen::Vector3d centre_in_square{0, -2, 2};

  ObliqueCamera() {
    camera.model = sfm::CameraModelId::kPinhole;
    camera.width = camera.height = 64;
    camera.params = {64, 64, 32, 32};
    Eigen::Matrix3d cam_from_square;
    const Eigen::Vector3d z = -centre_in_square.normalized(), x = Eigen::Vector3d::UnitX();
    cam_from_square.row(0) = x.transpose();
    cam_from_square.row(1) = z.cross(x).transpose();
    cam_from_square.row(2) = z.transpose();
    const Eigen::Matrix3d rotation = cam_from_square * kWorldFromSquare.transpose();
    cam_from_world.rotation = Eigen::Quaterniond(rotation);
    cam_from_world.translation = -(rotation * (kWorldFromSquare * centre_in_square));
  }

  // The square's point (its frame) seen at the centre of pixel (x, y).
  Eigen::Vector3d PointInSquareAt(int x, int y) const {
    const Eigen::Vector3d ray_in_square =
        kWorldFromSquare.transpose() * (cam_from_world.rotation.inverse() *
                                        camera.CamRayFromImage(Eigen::Vector2d(x + 0.5, y + 0.5)));
    return centre_in_square + (-centre_in_square.z() / ray_in_square.z()) * ray_in_square;
  }
  // The unit direction, in the square's frame, from that point to the camera.
  Eigen::Vector3d ToViewerInSquareAt(int x, int y) const {
    return (centre_in_square - PointInSquareAt(x, y)).normalized();
  }
};

double LinearGreenAt(const RenderedView& view, int x, int y) {
  return srgb::ToLinear(view.rgb.at<cv::Vec3f>(y, x)[1]);
}

TEST(ModelRenderer, ShadesEachPixelWithTheViewTermOfItsOwnView) {
  const ObliqueCamera cam;
  model::TexturedModel flat_response = FlatSquare(), with_term = FlatSquare();
  with_term.light_response.oren_nayar_b_over_a = 0.5;
  const ModelRenderer plain(flat_response), viewed(with_term);
  // A light on the camera's side of the normal, then one across it (square's frame).
  for (const Eigen::Vector3d& light_in_square :
       {Eigen::Vector3d(0, -0.5, std::sqrt(0.75)), Eigen::Vector3d(0.5, 0, std::sqrt(0.75))}) {
    sfm::ObjectLight l;
    l.direction_in_world = kWorldFromSquare * light_in_square;
    const RenderedView a = plain.Render(cam.camera, cam.cam_from_world, {l}, RenderMode::kPtm, 1);
    const RenderedView b = viewed.Render(cam.camera, cam.cam_from_world, {l}, RenderMode::kPtm, 1);
    for (const auto& [x, y] : {std::pair{32, 32}, std::pair{20, 40}, std::pair{44, 24}}) {
      // The face frame has z along the square's normal: the term is the same in any
      // frame turned about it, the square's too.
      const double expected =
          1.0 + 0.5 * ptm::OrenNayarTerm(light_in_square, cam.ToViewerInSquareAt(x, y));
      ASSERT_GT(LinearGreenAt(a, x, y), 0.05);
      EXPECT_NEAR(LinearGreenAt(b, x, y) / LinearGreenAt(a, x, y), expected, 2e-3)
          << "light " << light_in_square.transpose() << " pixel " << x << ", " << y;
    }
  }
  // The light on the camera's side brightens by a known amount at the centre
  // (alpha 45, beta 30 degrees: 1 + 0.5 sin 45 tan 30 = 1.204); across, not at all.
  EXPECT_NEAR(1.0 + 0.5 * ptm::OrenNayarTerm(Eigen::Vector3d(0, -0.5, std::sqrt(0.75)),
                                             cam.ToViewerInSquareAt(32, 32)),
              1.204, 0.01);
}

// FlatSquare's atlas position (pixels, centres at +0.5) of a point of the square.
Eigen::Vector2d AtlasPxOfSquarePoint(const Eigen::Vector3d& p) {
  return {16.0 + 15.0 * p.x(), 16.0 - 15.0 * p.y()};
}

// The luminance an atlas texel (x, y) holds: a quadratic, which a Catmull-Rom read
// reproduces between texel centres and a bilinear read does not.
double QuadraticLuminance(double x, double y) {
  return 0.3 + 0.0015 * ((x - 15.5) * (x - 15.5) + (y - 15.5) * (y - 15.5));
}

TEST(ModelRenderer, ReadsTheAtlasCatmullRomBetweenTexelCentres) {
  const ObliqueCamera cam;
  model::TexturedModel constant = FlatSquare(), quadratic = FlatSquare();
  ptm::Ptm& atlas = quadratic.atlases[0];
  for (int y = 0; y < atlas.height; ++y)
    for (int x = 0; x < atlas.width; ++x)
      atlas.Coefficients(static_cast<std::size_t>(y) * atlas.width + x)[5] =
          static_cast<float>(QuadraticLuminance(x, y));
  const ModelRenderer reference(constant), rendered(quadratic);
  sfm::ObjectLight zenith;  // along the square's normal: the luminance is a5
  zenith.direction_in_world = kWorldFromSquare * Eigen::Vector3d::UnitZ();
  const RenderedView a =
      reference.Render(cam.camera, cam.cam_from_world, {zenith}, RenderMode::kPtm, 1);
  const RenderedView b =
      rendered.Render(cam.camera, cam.cam_from_world, {zenith}, RenderMode::kPtm, 1);
  for (const auto& [x, y] :
       {std::pair{32, 32}, std::pair{20, 40}, std::pair{44, 24}, std::pair{27, 35}}) {
    const Eigen::Vector2d texel = AtlasPxOfSquarePoint(cam.PointInSquareAt(x, y)).array() - 0.5;
    ASSERT_TRUE(texel.minCoeff() > 1.0 && texel.maxCoeff() < 29.0) << texel.transpose();
    // The same light on both: their linear ratio is that of the luminances'.
    const double expected =
        srgb::ToLinear(static_cast<float>(QuadraticLuminance(texel.x(), texel.y()))) /
        srgb::ToLinear(0.6f);
    EXPECT_NEAR(LinearGreenAt(b, x, y) / LinearGreenAt(a, x, y), expected, 2e-5)
        << "pixel " << x << ", " << y << ", texel " << texel.transpose();
    // A bilinear read would miss by far more than that at these points.
    const double fx = texel.x() - std::floor(texel.x()), fy = texel.y() - std::floor(texel.y());
    const double x0 = std::floor(texel.x()), y0 = std::floor(texel.y());
    const double bilinear =
        (1 - fy) * ((1 - fx) * QuadraticLuminance(x0, y0) + fx * QuadraticLuminance(x0 + 1, y0)) +
        fy * ((1 - fx) * QuadraticLuminance(x0, y0 + 1) + fx * QuadraticLuminance(x0 + 1, y0 + 1));
    EXPECT_GT(
        std::abs(srgb::ToLinear(static_cast<float>(bilinear)) / srgb::ToLinear(0.6f) - expected),
        1e-4);
  }
}

}  // namespace
}  // namespace texlume::render
