#include "sfm/visibility.h"

#include <gtest/gtest.h>

#include "datasets_synthetic/object_scene.h"

namespace texlume::sfm {
namespace {

Reconstruction CamerasLookingAtOrigin(const std::vector<Eigen::Vector3d>& centers,
                                      CameraModelId model = CameraModelId::kPinhole) {
  Reconstruction r;
  Camera camera;
  camera.camera_id = CameraId(1);
  camera.model = model;
  camera.width = 640;
  camera.height = 480;
  camera.params = model == CameraModelId::kPinhole
                      ? std::vector<double>{600, 600, 320, 240}
                      : std::vector<double>{600, 600, 320, 240, -0.2, 0.05, 0.001, 0.001};
  r.cameras[camera.camera_id] = camera;
  std::uint32_t id = 1;
  for (const auto& c : centers) {
    Image image;
    image.image_id = ImageId(id);
    image.camera_id = camera.camera_id;
    image.name = "view" + std::to_string(id++) + ".png";
    image.cam_from_world = datasets::LookAt(c, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY());
    r.images[image.image_id] = image;
  }
  return r;
}

// Does the triangle overlap the open square |x|,|y| < h (separating axis test)?
bool OverlapsSquare(const mesh::TriangleMesh& m, std::size_t f, double h) {
  std::vector<Eigen::Vector2d> p = {m.Corner(f, 0).head<2>(), m.Corner(f, 1).head<2>(),
                                    m.Corner(f, 2).head<2>()};
  std::vector<Eigen::Vector2d> square = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  std::vector<Eigen::Vector2d> axes = {{1, 0}, {0, 1}};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d e =
        p[static_cast<std::size_t>((k + 1) % 3)] - p[static_cast<std::size_t>(k)];
    axes.emplace_back(-e.y(), e.x());
  }
  for (const auto& a : axes) {
    double t0 = 1e300, t1 = -1e300, s0 = 1e300, s1 = -1e300;
    for (const auto& q : p) t0 = std::min(t0, a.dot(q)), t1 = std::max(t1, a.dot(q));
    for (const auto& q : square) s0 = std::min(s0, a.dot(q)), s1 = std::max(s1, a.dot(q));
    if (t1 <= s0 || s1 <= t0) return false;
  }
  return true;
}

TEST(Visibility, KnownOccluderHidesExactlyTheTrianglesBehindItPartlyOrWholly) {
  // A 2x2 plane of 512 triangles at z = 0 and a 0.4x0.4 occluder at z = 1 facing
  // the camera at z = 3: its shadow on the plane is the square |x|,|y| < 0.3.
  mesh::TriangleMesh mesh = datasets::MakeGridPlane(16, 2.0);
  const std::size_t plane_faces = mesh.NumFaces();
  const int base = static_cast<int>(mesh.NumVertices());
  for (const auto& v : std::vector<Eigen::Vector3d>{
           {-0.2, -0.2, 1}, {0.2, -0.2, 1}, {0.2, 0.2, 1}, {-0.2, 0.2, 1}}) {
    mesh.vertices.push_back(v);
  }
  mesh.faces.push_back({base, base + 1, base + 2});
  mesh.faces.push_back({base, base + 2, base + 3});
  const Reconstruction r = CamerasLookingAtOrigin({{0, 0, 3}});
  const VisibilityResult vis = ComputeVisibility(mesh, r);
  int occluded = 0;
  for (std::size_t f = 0; f < plane_faces; ++f) {
    const bool behind = OverlapsSquare(mesh, f, 0.3);
    ASSERT_EQ(vis.triangles[f].FullyVisibleViews().empty(), behind) << "face " << f;
    occluded += behind ? 1 : 0;
    if (behind) {
      EXPECT_EQ(vis.triangles[f].best_view_source, vis.triangles[f].views.empty()
                                                       ? BestViewSource::kNone
                                                       : BestViewSource::kPartiallyVisible);
    } else {
      EXPECT_EQ(vis.triangles[f].best_view_source, BestViewSource::kFullyVisible);
      EXPECT_NEAR(vis.triangles[f].views[0].visible_fraction, 1.0, 1e-6);
    }
  }
  EXPECT_GT(occluded, 10);
  EXPECT_EQ(vis.triangles[plane_faces].best_view_source, BestViewSource::kFullyVisible);
  EXPECT_EQ(vis.num_fully_seen, mesh.NumFaces() - static_cast<std::size_t>(occluded));
}

TEST(Visibility, OccluderInsideATriangleWithAllCornersVisibleIsDetected) {
  // One big triangle; a tiny occluder in front of its middle hides no corner.
  mesh::TriangleMesh mesh;
  mesh.vertices = {{-1, -1, 0},         {1, -1, 0},         {0, 1, 0},
                   {-0.05, -0.05, 0.5}, {0.05, -0.05, 0.5}, {0, 0.05, 0.5}};
  mesh.faces = {{0, 1, 2}, {3, 4, 5}};
  const VisibilityResult vis = ComputeVisibility(mesh, CamerasLookingAtOrigin({{0, 0, 4}}));
  ASSERT_EQ(vis.triangles[0].views.size(), 1u);
  EXPECT_FALSE(vis.triangles[0].views[0].fully_visible);
  EXPECT_GT(vis.triangles[0].views[0].visible_fraction, 0.95);
  EXPECT_LT(vis.triangles[0].views[0].visible_fraction, 1.0);
  EXPECT_TRUE(vis.triangles[1].views[0].fully_visible);
}

TEST(Visibility, BestViewIsTheSmallestAngleAmongFullyVisibleViews) {
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(4, 0.5);
  const Reconstruction r = CamerasLookingAtOrigin({{3, 0, 2}, {0.3, 0, 4}, {-2, 0, 2}, {0, 0, -3}});
  const VisibilityResult vis = ComputeVisibility(mesh, r);
  for (const TriangleVisibility& t : vis.triangles) {
    EXPECT_EQ(t.best_view, ImageId(2));
    EXPECT_EQ(t.best_view_source, BestViewSource::kFullyVisible);
    // The camera below the plane sees its back: no record.
    EXPECT_EQ(t.views.size(), 3u);
    EXPECT_EQ(t.FullyVisibleViews().size(), 3u);
    for (const TriangleView& v : t.views) {
      const Eigen::Vector3d c = r.images.at(v.image_id).ProjectionCenter();
      EXPECT_NEAR(v.angle_rad, std::acos(c.normalized().z()), 0.1);  // centroid near origin
    }
  }
}

TEST(Visibility, ProjectedAreaMatchesTheHeadOnScale) {
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(2, 0.2);
  const VisibilityResult vis = ComputeVisibility(mesh, CamerasLookingAtOrigin({{0, 0, 3}}));
  double area_px = 0;
  for (const auto& t : vis.triangles) area_px += t.views.at(0).projected_area_px;
  // 0.2 x 0.2 world units at distance 3 with f = 600: (0.2 * 200)^2 pixels, to within
  // the perspective of the plane's extent.
  EXPECT_NEAR(area_px, 40.0 * 40.0, 40.0 * 40.0 * 0.01);
}

TEST(Visibility, TrianglesLeavingTheImageFallBackToTheirMostVisibleView) {
  // A plane wider than the field of view: outer triangles are only partly inside.
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(8, 8.0);
  const VisibilityResult vis =
      ComputeVisibility(mesh, CamerasLookingAtOrigin({{0, 0, 3}}, CameraModelId::kOpenCV));
  EXPECT_GT(vis.num_fully_seen, 0u);
  EXPECT_GT(vis.num_partially_seen, 0u);
  EXPECT_GT(vis.num_unseen, 0u);
  EXPECT_EQ(vis.num_fully_seen + vis.num_partially_seen + vis.num_unseen, mesh.NumFaces());
  for (const auto& t : vis.triangles) {
    if (t.best_view_source == BestViewSource::kPartiallyVisible) {
      EXPECT_TRUE(t.best_view.IsValid());
      EXPECT_LT(t.views[0].visible_fraction, 1.0f);
    }
    if (t.best_view_source == BestViewSource::kNone) {
      EXPECT_FALSE(t.best_view.IsValid());
    }
  }
}

TEST(Visibility, DownscaledBuffersAgreeOnASphere) {
  const datasets::ObjectScene scene = datasets::MakeObjectScene({});
  VisibilityOptions coarse;
  coarse.max_buffer_dimension = 160;
  const VisibilityResult full = ComputeVisibility(scene.mesh, scene.reconstruction);
  const VisibilityResult small = ComputeVisibility(scene.mesh, scene.reconstruction, coarse);
  std::size_t same_best = 0;
  for (std::size_t f = 0; f < full.triangles.size(); ++f) {
    same_best += full.triangles[f].best_view == small.triangles[f].best_view ? 1 : 0;
  }
  EXPECT_GT(static_cast<double>(same_best) / static_cast<double>(full.triangles.size()), 0.97);
}

TEST(Visibility, OptionsAreChecked) {
  VisibilityOptions o;
  o.max_buffer_dimension = 4;
  EXPECT_THROW(o.Check(), std::invalid_argument);
  o = {};
  o.depth_tolerance_relative = 0;
  EXPECT_THROW(o.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace texlume::sfm
