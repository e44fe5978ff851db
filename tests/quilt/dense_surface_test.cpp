#include "quilt/dense_surface.h"

#include <gtest/gtest.h>

#include <queue>

#include "datasets_synthetic/shapes.h"

namespace texlume::quilt {
namespace {

struct Dense {
  synth::PatchGeometry geometry;
  atlas::AtlasLayout layout;
  DenseSurface surface;
};

Dense MakeDense(const mesh::TriangleMesh& mesh, double texel, atlas::AtlasMode mode,
                atlas::ChartFlattening flattening) {
  Dense d;
  d.geometry = synth::MakePatchGeometry(mesh, texel, 4, synth::TangentFrame::kFirstEdge,
                                        Eigen::Vector3d::UnitZ());
  atlas::AtlasOptions o;
  o.mode = mode;
  o.flattening = flattening;
  o.atlas_size = 1024;
  o.max_chart_size = 256;
  d.layout = atlas::LayoutAtlases(mesh, d.geometry.patches, d.geometry.unfoldings, texel, o);
  d.surface = DenseSurface::Build(mesh, d.layout, d.geometry.patches, d.geometry.unfoldings, texel);
  return d;
}

double Area(const mesh::TriangleMesh& mesh) {
  double area = 0;
  for (const auto& f : mesh.faces)
    area += 0.5 * (mesh.vertices[static_cast<std::size_t>(f[1])] -
                   mesh.vertices[static_cast<std::size_t>(f[0])])
                      .cross(mesh.vertices[static_cast<std::size_t>(f[2])] -
                             mesh.vertices[static_cast<std::size_t>(f[0])])
                      .norm();
  return area;
}

std::size_t Reached(const DenseSurface& surface) {
  std::vector<bool> seen(surface.size(), false);
  std::queue<int> queue;
  queue.push(0);
  seen[0] = true;
  std::size_t reached = 1;
  while (!queue.empty()) {
    const int s = queue.front();
    queue.pop();
    for (const int n : surface.Neighbours(s))
      if (!seen[static_cast<std::size_t>(n)]) {
        seen[static_cast<std::size_t>(n)] = true;
        ++reached;
        queue.push(n);
      }
  }
  return reached;
}

// Every atlas texel inside a triangle is one sample, and the samples cover the
// surface at the texel spacing.
TEST(DenseSurface, OneSamplePerTexelInsideATriangle) {
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(4, 0.5);  // 32 faces, one chart
  const double texel = 0.005;
  const Dense d =
      MakeDense(plane, texel, atlas::AtlasMode::kCharts, atlas::ChartFlattening::kRigid);
  ASSERT_EQ(d.layout.num_charts, 1);
  EXPECT_EQ(d.surface.chart_seam_links(), 0u);
  const atlas::AtlasCoverage coverage = atlas::VisitAtlasTexels(
      d.layout, texel, 0, [](int, int, int, int, const Eigen::Vector2d&) {});
  EXPECT_EQ(d.surface.size(), coverage.inside_texels);
  EXPECT_NEAR(d.surface.size() * texel * texel / Area(plane), 1.0, 0.01);
  for (std::size_t s = 0; s < d.surface.size(); ++s) {
    const DenseSample& a = d.surface.samples()[s];
    ASSERT_EQ(d.surface.At(a.atlas, a.x, a.y), static_cast<int>(s));
    EXPECT_LT(std::abs(d.surface.PointInWorld(static_cast<int>(s)).z()), 1e-9);  // on the plane
  }
}

// Per-triangle boxes put every face in a chart of its own: the links across
// them zip the plane into one piece, with neighbours about a texel apart.
TEST(DenseSurface, LinksCrossChartsAtTheTexelSpacing) {
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(4, 0.5);
  const double texel = 0.005;
  const Dense d =
      MakeDense(plane, texel, atlas::AtlasMode::kPerTriangle, atlas::ChartFlattening::kRigid);
  EXPECT_EQ(Reached(d.surface), d.surface.size());
  EXPECT_GT(d.surface.chart_seam_links(), 0u);
  double sum = 0, longest = 0;
  for (std::size_t s = 0; s < d.surface.size(); ++s)
    for (const int n : d.surface.Neighbours(static_cast<int>(s))) {
      const double length =
          (d.surface.PointInWorld(static_cast<int>(s)) - d.surface.PointInWorld(n)).norm();
      sum += length, longest = std::max(longest, length);
    }
  // Within charts links are one texel; across, up to a diagonal.
  EXPECT_GT(sum / (2.0 * d.surface.links()) / texel, 0.99);
  EXPECT_LT(sum / (2.0 * d.surface.links()) / texel, 1.1);
  EXPECT_LT(longest / texel, 2.0);
  // Open directions: the plane's border (about 4 x 100 texels), and few more.
  EXPECT_GT(d.surface.open_directions(), 350u);
  EXPECT_LT(d.surface.open_directions(), 600u);
}

// A closed surface in conformal charts: one connected piece, no border.
TEST(DenseSurface, AClosedSurfaceIsOnePieceWithoutBorder) {
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(2, 1.0);  // 320 faces
  const double texel = 0.04;
  const Dense d =
      MakeDense(sphere, texel, atlas::AtlasMode::kCharts, atlas::ChartFlattening::kConformal);
  ASSERT_GT(d.layout.num_charts, 1);
  EXPECT_EQ(Reached(d.surface), d.surface.size());
  EXPECT_GT(d.surface.chart_seam_links(), 0u);
  EXPECT_LT(d.surface.open_directions(), d.surface.size() / 100);
  for (std::size_t s = 0; s < d.surface.size(); ++s)
    for (const int n : d.surface.Neighbours(static_cast<int>(s)))
      EXPECT_LT((d.surface.PointInWorld(static_cast<int>(s)) - d.surface.PointInWorld(n)).norm(),
                2.5 * texel);
}

}  // namespace
}  // namespace texlume::quilt
