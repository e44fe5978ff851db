#include "synth/charts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "datasets_synthetic/shapes.h"
#include "sfm/errors.h"
#include "synth/atlas.h"
#include "synth/triangle_frame.h"

namespace texlume::synth {
namespace {

constexpr double kTexel = 0.002;  // the default material's texel size (world units)

PatchGeometry Geometry(const sfm::TriangleMesh& mesh) {
  return MakePatchGeometry(mesh, kTexel, 8, TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
}

TEST(Charts, SingularValuesOfKnownMaps) {
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(0.7).toRotationMatrix();
  EXPECT_TRUE(SingularValues2(rotation).isApprox(Eigen::Vector2d(1, 1)));
  EXPECT_TRUE(
      SingularValues2(rotation * Eigen::Vector2d(3, 0.5).asDiagonal() * rotation.transpose())
          .isApprox(Eigen::Vector2d(3, 0.5)));
  Eigen::Matrix2d shear;
  shear << 1, 1, 0, 1;  // singular values: golden ratio and its inverse
  const double phi = 0.5 * (1 + std::sqrt(5.0));
  EXPECT_TRUE(SingularValues2(shear).isApprox(Eigen::Vector2d(phi, 1 / phi)));
}

// A plane is flattened without distortion: one chart, every face's map a rotation.
TEST(Charts, ConformalMapOfAPlaneIsAnIsometry) {
  const sfm::TriangleMesh mesh = datasets::MakeGridPlane(8, 0.5);  // 128 faces, 250 texels
  const PatchGeometry g = Geometry(mesh);
  ConformalChartOptions o;
  o.texel_size = kTexel;
  ConformalChartStats stats;
  const auto charts = MakeConformalCharts(mesh, g.patches, g.unfoldings, o, &stats);
  ASSERT_EQ(charts.size(), 1u);
  EXPECT_EQ(charts[0].size(), mesh.faces.size());
  EXPECT_EQ(stats.splits, 0);
  for (const ChartFace& cf : charts[0]) {
    const Eigen::Vector2d s = SingularValues2(cf.linear);
    EXPECT_NEAR(s.x(), 1.0, 1e-6);
    EXPECT_NEAR(s.y(), 1.0, 1e-6);
    EXPECT_GT(cf.linear.determinant(), 0.0);  // not mirrored
  }
}

// On a sphere (curved everywhere) every face lands in exactly one chart, no face
// is flipped, and every face's stretch stays within the bound; a tighter bound
// splits charts into more.
TEST(Charts, ConformalChartsOfASphereStayWithinTheStretchBound) {
  const sfm::TriangleMesh mesh = datasets::MakeIcosphere(3, 1.0);  // 1280 faces
  const PatchGeometry g = Geometry(mesh);
  ConformalChartOptions o;
  o.texel_size = kTexel;
  o.max_side_texels = 600;
  std::size_t previous_charts = 0;
  for (const double bound : {1.25, 1.05}) {
    o.max_stretch = bound;
    const auto charts = MakeConformalCharts(mesh, g.patches, g.unfoldings, o);
    std::set<int> seen;
    double worst = 1.0;
    for (const auto& chart : charts)
      for (const ChartFace& cf : chart) {
        EXPECT_TRUE(seen.insert(cf.face).second) << "face " << cf.face << " in two charts";
        EXPECT_GT(cf.linear.determinant(), 0.0);
        const Eigen::Vector2d s = SingularValues2(cf.linear);
        worst = std::max({worst, s.x(), 1.0 / s.y()});
      }
    EXPECT_EQ(seen.size(), mesh.faces.size());
    EXPECT_LE(worst, bound + 1e-9);
    EXPECT_GT(worst, 1.0 + 1e-3);  // curved: not an isometry
    EXPECT_GT(charts.size(), previous_charts);
    previous_charts = charts.size();
  }
}

// A conformal layout: the atlas frame (dP/du, n x dP/du, n) that a renderer
// derives from the texture coordinates is the triangle frame turned by
// AtlasFrameAngle, and FrameFromAtlas inverts the placement.
TEST(Charts, ConformalLayoutAgreesWithTheTextureCoordinates) {
  const sfm::TriangleMesh mesh = datasets::CoarseMesh(datasets::SceneShape::kTorus);
  const PatchGeometry g = Geometry(mesh);
  AtlasOptions o;
  o.flattening = ChartFlattening::kConformal;
  o.max_chart_size = 384;
  const AtlasLayout layout = LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
  EXPECT_LT(layout.num_charts, static_cast<int>(mesh.faces.size()) / 10);
  const AtlasStretch stretch = MeasureStretch(g.patches, layout);
  EXPECT_GE(stretch.min, 1 / o.max_chart_stretch - 1e-9);
  EXPECT_LE(stretch.max, o.max_chart_stretch + 1e-9);
  EXPECT_NEAR(stretch.mean, 1.0, 0.01);  // charts keep the surface's area
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const FacePlacement& fp = layout.faces[f];
    const TrianglePatch& patch = g.patches[f];
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(fp.FrameFromAtlas(fp.corners_px[static_cast<std::size_t>(k)], kTexel)
                      .isApprox(patch.corners_in_frame[static_cast<std::size_t>(k)], 1e-9));
    const auto& c = fp.corners_px;
    const Eigen::Vector3d e1 = mesh.Corner(f, 1) - mesh.Corner(f, 0);
    const Eigen::Vector3d e2 = mesh.Corner(f, 2) - mesh.Corner(f, 0);
    const double du1 = c[1].x() - c[0].x(), dv1 = -(c[1].y() - c[0].y());
    const double du2 = c[2].x() - c[0].x(), dv2 = -(c[2].y() - c[0].y());
    const Eigen::Vector3d dp_du = (e1 * dv2 - e2 * dv1) / (du1 * dv2 - du2 * dv1);
    const double angle = fp.AtlasFrameAngle();
    const Eigen::Vector3d x_atlas =
        std::cos(angle) * patch.frame.x_axis + std::sin(angle) * patch.frame.y_axis;
    EXPECT_GT(x_atlas.dot(dp_du.normalized()), 1.0 - 1e-9) << "face " << f;
  }
}

// Options out of range are refused.
TEST(Charts, BadChartOptionsAreRefused) {
  AtlasOptions o;
  o.max_chart_stretch = 1.0;
  EXPECT_THROW(o.Check(), OptionError);
  o.max_chart_stretch = 5.0;
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace texlume::synth
