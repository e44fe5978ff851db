#include "quilt/image_term.h"

#include <gtest/gtest.h>

#include <numbers>

#include "datasets_synthetic/material.h"
#include "datasets_synthetic/object_scene.h"
#include "datasets_synthetic/shapes.h"
#include "synth/triangle_parts.h"

namespace texlume::quilt {
namespace {

constexpr double kTexel = 0.01;  // world units; the plane is 0.4 wide: 40 texels

// A plane at z = 0 seen from above under one light, and the sample
// position every point of it truly shows: the sample's x along the world
// direction (cos a, sin a, 0), its y (up) a quarter turn on, texel
// (kTruthX, kTruthY) at the origin.
constexpr double kTruthX = 60.3, kTruthY = 57.6;

Eigen::Vector2d TruthAt(const Eigen::Vector3d& point_in_world, double a) {
  const double u = point_in_world.x() * std::cos(a) + point_in_world.y() * std::sin(a);
  const double v = -point_in_world.x() * std::sin(a) + point_in_world.y() * std::cos(a);
  return {kTruthX + u / kTexel, kTruthY - v / kTexel};
}

struct PhotographedPlane {
  mesh::TriangleMesh mesh = datasets::MakeGridPlane(4, 0.4);
  synth::PatchGeometry geometry;
  atlas::AtlasLayout layout;
  DenseSurface dense;
  sfm::Reconstruction reconstruction;
  std::vector<synth::MeshPhoto> photos;
  sfm::VisibilityResult visibility;
  synth::TriangleSynthesis photometry;
  double truth_rad = 0;
};

// The sample's raw coefficients and colour, bilinear at a sample position.
void RawAt(const ptm::Ptm& ptm, const Eigen::Vector2d& p, float out[9]) {
  const double x = std::clamp(p.x() - 0.5, 0.0, ptm.width - 1.001);
  const double y = std::clamp(p.y() - 0.5, 0.0, ptm.height - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double fx = x - x0, fy = y - y0;
  std::fill_n(out, 9, 0.0f);
  for (int k = 0; k < 4; ++k) {
    const int xi = x0 + (k & 1), yi = y0 + (k >> 1);
    const double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
    const std::size_t t = static_cast<std::size_t>(yi) * ptm.width + xi;
    for (int c = 0; c < 6; ++c) out[c] += static_cast<float>(w * ptm.Coefficients(t)[c]);
    for (int c = 0; c < 3; ++c) out[6 + c] += static_cast<float>(w * ptm.colour[t * 3 + c]);
  }
}

// One photo from straight above (1.5 photo pixels per texel), rendered from
// the truth (the sample turned by `truth_rad`) under a light from the upper right.
PhotographedPlane Photograph(const ptm::Ptm& ptm, double truth_rad,
                             atlas::AtlasMode mode = atlas::AtlasMode::kCharts) {
  PhotographedPlane s;
  s.truth_rad = truth_rad;
  s.geometry = synth::MakePatchGeometry(s.mesh, kTexel, 4, synth::TangentFrame::kFirstEdge,
                                        Eigen::Vector3d::UnitZ());
  atlas::AtlasOptions o;
  o.mode = mode;
  o.flattening = atlas::ChartFlattening::kRigid;
  o.atlas_size = 256;
  s.layout = atlas::LayoutAtlases(s.mesh, s.geometry.patches, s.geometry.unfoldings, kTexel, o);
  s.dense =
      DenseSurface::Build(s.mesh, s.layout, s.geometry.patches, s.geometry.unfoldings, kTexel);

  sfm::Camera camera;
  camera.camera_id = sfm::CameraId(1);
  camera.width = camera.height = 100;
  camera.params = {150, 150, 50, 50};  // at distance 1: 150 px per world unit
  s.reconstruction.cameras[camera.camera_id] = camera;
  sfm::Image image;
  image.image_id = sfm::ImageId(1);
  image.camera_id = camera.camera_id;
  image.name = "above.png";
  image.cam_from_world =
      datasets::LookAt(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY());
  s.reconstruction.images[image.image_id] = image;

  synth::MeshPhoto photo;
  photo.image_id = image.image_id;
  photo.name = image.name;
  sfm::ObjectLight light;
  light.direction_in_world = Eigen::Vector3d(0.5, 0.3, 0.8).normalized();
  const Eigen::Vector3d& l = light.direction_in_world;
  const double c = std::cos(truth_rad), sn = std::sin(truth_rad);
  const Eigen::Vector3d light_in_sample(c * l.x() + sn * l.y(), -sn * l.x() + c * l.y(), l.z());
  photo.lights = {light};
  cv::Mat pixels = cv::Mat::zeros(100, 100, CV_32FC3);
  const sfm::Rigid3d world_from_cam = image.cam_from_world.Inverse();
  for (int v = 0; v < 100; ++v)
    for (int u = 0; u < 100; ++u) {
      const Eigen::Vector3d ray =
          world_from_cam.rotation * camera.CamRayFromImage(Eigen::Vector2d(u + 0.5, v + 0.5));
      const Eigen::Vector3d centre = world_from_cam.translation;
      const Eigen::Vector3d on_plane = centre - centre.z() / ray.z() * ray;
      float raw[9];
      RawAt(ptm, TruthAt(on_plane, truth_rad), raw);
      const Eigen::Vector3f rgb = synth::RelightMixture(
          raw, raw + 6, ptm.format, {{light_in_sample, 1.0}}, 1.0, {}, Eigen::Vector3d::UnitZ());
      pixels.at<cv::Vec3f>(v, u) = cv::Vec3f(rgb.x(), rgb.y(), rgb.z());
    }
  photo.pixels = PhotoPixels(pixels);
  s.photos.push_back(photo);
  s.visibility = sfm::ComputeVisibility(s.mesh, s.reconstruction);
  s.photometry.photo_gains = {1.0};
  return s;
}

// The share of dense samples whose lookup lies within a texel of the truth.
double ShareAtTruth(const PhotographedPlane& s, const QuiltResult& r) {
  std::size_t near = 0;
  for (std::size_t i = 0; i < s.dense.size(); ++i) {
    const Eigen::Vector2d truth = TruthAt(s.dense.PointInWorld(static_cast<int>(i)), s.truth_rad);
    near += (r.lookups[i].sample_px.cast<double>() - truth).norm() < 1.0;
  }
  return static_cast<double>(near) / static_cast<double>(s.dense.size());
}

// The plane quilted in small work patches along a world direction, with the
// photo's image term.
QuiltResult QuiltFollowingThePhoto(const PhotographedPlane& s, const synth::PtmSample& sample,
                                   const Eigen::Vector3d& field_in_world) {
  QuiltOptions o;
  o.work_patch_levels = 12;
  o.field_in_world.assign(s.mesh.faces.size(), field_in_world);
  const PhotoEvidence evidence{s.reconstruction, s.visibility, s.photos, s.photometry};
  PhotoImageTerm term(s.dense, s.layout, sample, evidence, {});
  return QuiltSurface(s.dense, s.layout, sample, o, {}, nullptr, &term);
}

// With the image term, the quilt puts the sample where the photo shows it:
// most patches are placed among the photo's best placements, and nearly every
// sample looks up the position the photo was rendered from. Without it, the
// first patch lands at random and the rest follow it.
TEST(PhotoImageTerm, PlacesTheSampleWhereThePhotoShowsIt) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(128, 3);
  const synth::PtmSample sample(ptm);
  const PhotographedPlane s = Photograph(ptm, 0.0);
  ASSERT_TRUE(s.visibility.triangles[0].views[0].fully_visible);
  const QuiltResult with = QuiltFollowingThePhoto(s, sample, Eigen::Vector3d::UnitX());
  QuiltOptions o;
  o.work_patch_levels = 12;
  o.field_in_world.assign(s.mesh.faces.size(), Eigen::Vector3d::UnitX());
  const QuiltResult without = QuiltSurface(s.dense, s.layout, sample, o);
  ASSERT_GT(with.stats.patches, 3u);
  // Patches that only fill gaps too small for a photo pixel match the overlap alone.
  EXPECT_GE(with.stats.photo_patches * 4, with.stats.patches * 3);
  EXPECT_EQ(without.stats.photo_patches, 0u);
  EXPECT_GT(ShareAtTruth(s, with), 0.95);
  EXPECT_LT(ShareAtTruth(s, without), 0.2);
}

// The sample turned a quarter on the plane, and the field with it: the copy
// is relit under the light turned back into the sample's frame, so the image
// term still finds where the photo shows it.
TEST(PhotoImageTerm, TurnsTheLightsWithTheCopy) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(128, 4);
  const synth::PtmSample sample(ptm);
  const PhotographedPlane s = Photograph(ptm, std::numbers::pi / 2);
  const QuiltResult r = QuiltFollowingThePhoto(s, sample, Eigen::Vector3d::UnitY());
  EXPECT_GT(ShareAtTruth(s, r), 0.95);
}

// Every face its own chart: patches cross charts, and their work images are
// the conformal maps of their faces, turned so that the seed's chart keeps its
// atlas frame (the frame the photos' lights are laid in).
TEST(PhotoImageTerm, FollowsThePhotoAcrossCharts) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(128, 5);
  const synth::PtmSample sample(ptm);
  const PhotographedPlane s = Photograph(ptm, 0.0, atlas::AtlasMode::kPerTriangle);
  ASSERT_GT(s.dense.chart_seam_links(), 0u);
  const QuiltResult r = QuiltFollowingThePhoto(s, sample, Eigen::Vector3d::UnitX());
  EXPECT_GT(ShareAtTruth(s, r), 0.95);
}

}  // namespace
}  // namespace texlume::quilt
