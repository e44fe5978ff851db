#include "atlas/charts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <opencv2/core.hpp>
#include <random>
#include <set>

#include "atlas/atlas.h"
#include "core/check.h"
#include "core/errors.h"
#include "datasets_synthetic/shapes.h"
#include "mesh/triangle_frame.h"
#include "pipeline/synth_job.h"

namespace texlume::synth {
namespace {

constexpr double kTexel = 0.002;  // the default material's texel size (world units)
constexpr double kPi = 3.14159265358979323846;

PatchGeometry Geometry(const mesh::TriangleMesh& mesh) {
  return MakePatchGeometry(mesh, kTexel, 8, TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
}

/// Every one of `num_faces` faces is in exactly one chart.
void ExpectEachFaceInOneChart(const std::vector<std::vector<atlas::ChartFace>>& charts,
                              std::size_t num_faces) {
  std::set<int> seen;
  for (const auto& chart : charts)
    for (const atlas::ChartFace& cf : chart)
      EXPECT_TRUE(seen.insert(cf.face).second) << "face " << cf.face << " in two charts";
  EXPECT_EQ(seen.size(), num_faces);
}

/// The 1280-face icosphere with every vertex moved along the sphere by up to a
/// third of an edge (seeded): an irregular mesh.
mesh::TriangleMesh JitteredIcosphere(unsigned seed) {
  return datasets::MakeScanLikeMesh(3, 1.0, 0.0, seed);
}

// Strip charts of the mesh, every face in exactly one of them.
std::vector<std::vector<atlas::ChartFace>> CheckedStripCharts(
    const mesh::TriangleMesh& mesh, const PatchGeometry& g, const atlas::StripChartOptions& o,
    atlas::StripChartStats* stats = nullptr) {
  auto charts = atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, o, stats);
  ExpectEachFaceInOneChart(charts, mesh.faces.size());
  return charts;
}

TEST(Charts, SingularValuesOfKnownMaps) {
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(0.7).toRotationMatrix();
  EXPECT_TRUE(atlas::SingularValues2(rotation).isApprox(Eigen::Vector2d(1, 1)));
  EXPECT_TRUE(
      atlas::SingularValues2(rotation * Eigen::Vector2d(3, 0.5).asDiagonal() * rotation.transpose())
          .isApprox(Eigen::Vector2d(3, 0.5)));
  Eigen::Matrix2d shear;
  shear << 1, 1, 0, 1;  // singular values: golden ratio and its inverse
  const double phi = 0.5 * (1 + std::sqrt(5.0));
  EXPECT_TRUE(atlas::SingularValues2(shear).isApprox(Eigen::Vector2d(phi, 1 / phi)));
}

// A plane is flattened without distortion: one chart, every face's map a rotation.
TEST(Charts, ConformalMapOfAPlaneIsAnIsometry) {
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(8, 0.5);  // 128 faces, 250 texels
  const PatchGeometry g = Geometry(mesh);
  atlas::ConformalChartOptions o;
  o.texel_size = kTexel;
  atlas::ConformalChartStats stats;
  const auto charts = atlas::MakeConformalCharts(mesh, g.patches, g.unfoldings, o, &stats);
  ASSERT_EQ(charts.size(), 1u);
  EXPECT_EQ(charts[0].size(), mesh.faces.size());
  EXPECT_EQ(stats.splits, 0);
  for (const atlas::ChartFace& cf : charts[0]) {
    const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
    EXPECT_NEAR(s.x(), 1.0, 1e-6);
    EXPECT_NEAR(s.y(), 1.0, 1e-6);
    EXPECT_GT(cf.linear.determinant(), 0.0);  // not mirrored
  }
}

// On a sphere (curved everywhere) every face lands in exactly one chart, no face
// is flipped, and every face's stretch stays within the bound; a tighter bound
// splits charts into more.
TEST(Charts, ConformalChartsOfASphereStayWithinTheStretchBound) {
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(3, 1.0);  // 1280 faces
  const PatchGeometry g = Geometry(mesh);
  atlas::ConformalChartOptions o;
  o.texel_size = kTexel;
  o.max_side_texels = 600;
  std::size_t previous_charts = 0;
  for (const double bound : {1.25, 1.05}) {
    o.max_stretch = bound;
    const auto charts = atlas::MakeConformalCharts(mesh, g.patches, g.unfoldings, o);
    ExpectEachFaceInOneChart(charts, mesh.faces.size());
    double worst = 1.0;
    for (const auto& chart : charts)
      for (const atlas::ChartFace& cf : chart) {
        EXPECT_GT(cf.linear.determinant(), 0.0);
        const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
        worst = std::max({worst, s.x(), 1.0 / s.y()});
      }
    EXPECT_LE(worst, bound + 1e-9);
    EXPECT_GT(worst, 1.0 + 1e-3);  // curved: not an isometry
    EXPECT_GT(charts.size(), previous_charts);
    previous_charts = charts.size();
  }
}

// The atlas frame (dP/du, n x dP/du, n) that a renderer derives from the
// texture coordinates is the triangle frame turned by AtlasFrameAngle, and
// FrameFromAtlas inverts the placement.
void ExpectLayoutAgreesWithTextureCoordinates(const mesh::TriangleMesh& mesh,
                                              const PatchGeometry& g,
                                              const atlas::AtlasLayout& layout) {
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const atlas::FacePlacement& fp = layout.faces[f];
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

TEST(Charts, ConformalLayoutAgreesWithTheTextureCoordinates) {
  const mesh::TriangleMesh mesh = datasets::CoarseMesh(datasets::SceneShape::kTorus);
  const PatchGeometry g = Geometry(mesh);
  atlas::AtlasOptions o;
  o.flattening = atlas::ChartFlattening::kConformal;
  o.max_chart_size = 384;
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
  EXPECT_LT(layout.num_charts, static_cast<int>(mesh.faces.size()) / 10);
  const atlas::AtlasStretch stretch = atlas::MeasureStretch(g.patches, layout);
  EXPECT_GE(stretch.min, 1 / o.max_chart_stretch - 1e-9);
  EXPECT_LE(stretch.max, o.max_chart_stretch + 1e-9);
  EXPECT_NEAR(stretch.mean, 1.0, 0.01);  // charts keep the surface's area
  ExpectLayoutAgreesWithTextureCoordinates(mesh, g, layout);
}

/// Per strip chart: every face has its corners on two band lines, which lie a
/// hair (1e-3 texels) from texel centres; a chart has two lines unless its
/// bands are `stacked`; no texel centre lies more than half a texel inside two
/// of its faces; no face is flipped or stretched beyond `bound`; and a vertex
/// shared by faces of the chart has one place in it (or places far apart).
void ExpectBands(const std::vector<std::vector<atlas::ChartFace>>& charts, const PatchGeometry& g,
                 const mesh::TriangleMesh& mesh, double bound, bool stacked = false) {
  for (const auto& chart : charts) {
    if (chart.size() == 1 && chart[0].linear.isIdentity()) continue;  // a lone face
    std::set<long> ys;
    std::set<std::pair<int, int>> inside;
    // Places of a vertex in the chart: one, or far apart (a band that wraps
    // around, cut where it meets itself).
    std::map<int, std::vector<Eigen::Vector2d>> places_of_vertex;
    for (const atlas::ChartFace& cf : chart) {
      EXPECT_GT(cf.linear.determinant(), 0.0);
      const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
      EXPECT_LE(s.x(), bound + 1e-9);
      EXPECT_GE(s.y(), 1 / bound - 1e-9);
      std::array<Eigen::Vector2d, 3> q;
      std::set<long> face_ys;
      for (std::size_t k = 0; k < 3; ++k) {
        q[k] = (cf.linear * g.patches[static_cast<std::size_t>(cf.face)].corners_in_frame[k] +
                cf.translation) /
               kTexel;
        ys.insert(std::lround(q[k].y() * 1000));  // on a line to 1e-3 texels
        face_ys.insert(std::lround(q[k].y() * 1000));
        const double off_centre = q[k].y() - 0.5 - std::round(q[k].y() - 0.5);
        EXPECT_NEAR(std::abs(off_centre), 1e-3, 1e-6) << "a corner off the lines";
        const int v = mesh.faces[static_cast<std::size_t>(cf.face)][k];
        for (const Eigen::Vector2d& other : places_of_vertex[v]) {
          const double d = (other - q[k]).norm();
          EXPECT_TRUE(d < 1e-6 || d > 4.0)
              << "vertex " << v << " has two places " << d << " texels apart";
        }
        places_of_vertex[v].push_back(q[k]);
      }
      EXPECT_EQ(face_ys.size(), 2u) << "a face's corners lie on more than two lines";
      const Eigen::Vector2d lo = q[0].cwiseMin(q[1]).cwiseMin(q[2]);
      const Eigen::Vector2d hi = q[0].cwiseMax(q[1]).cwiseMax(q[2]);
      for (int y = static_cast<int>(std::floor(lo.y())); y <= static_cast<int>(hi.y()); ++y)
        for (int x = static_cast<int>(std::floor(lo.x())); x <= static_cast<int>(hi.x()); ++x)
          if (mesh::SignedDistanceToTriangle(q, Eigen::Vector2d(x + 0.5, y + 0.5)) < -0.5) {
            EXPECT_TRUE(inside.emplace(x, y).second) << "faces overlap at " << x << ", " << y;
          }
    }
    if (!stacked) {
      EXPECT_EQ(ys.size(), 2u) << "a strip's corners lie on more than two lines";
    }
  }
}

// A grid of right triangles maps onto bands almost rigidly: one band per row
// of quads, whole texels high (so the only stretch is rounding the height).
TEST(Charts, StripsOfAGridPlaneAreRowsOfQuads) {
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(8, 0.5);  // 128 faces, 250 texels
  const PatchGeometry g = Geometry(mesh);
  atlas::StripChartOptions o;
  o.texel_size = kTexel;
  atlas::StripChartStats stats;
  const auto charts = CheckedStripCharts(mesh, g, o, &stats);
  EXPECT_EQ(charts.size(), 8u);
  EXPECT_EQ(stats.strips, 8);
  EXPECT_EQ(stats.lone_faces, 0);
  for (const auto& chart : charts) {
    EXPECT_EQ(chart.size(), 16u);
    for (const atlas::ChartFace& cf : chart) {
      const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
      EXPECT_NEAR(s.x(), 1.0, 0.01);  // 31.25 texels rounded to 31
      EXPECT_NEAR(s.y(), 1.0, 0.01);
    }
  }
  ExpectBands(charts, g, mesh, o.max_stretch);
}

// Stacked, the grid plane's bands share their lines: one chart of 8 bands,
// every vertex in one place, and still no stretch but the rounding of heights.
TEST(Charts, StackedBandsOfAGridPlaneAreOneChart) {
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(8, 0.5);
  const PatchGeometry g = Geometry(mesh);
  atlas::StripChartOptions o;
  o.texel_size = kTexel;
  o.max_stack_texels = 8 * 31;
  atlas::StripChartStats stats;
  const auto charts = CheckedStripCharts(mesh, g, o, &stats);
  ASSERT_EQ(charts.size(), 1u);
  EXPECT_EQ(stats.strips, 1);
  EXPECT_EQ(stats.stacked, 7);
  for (const atlas::ChartFace& cf : charts[0]) {
    const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
    EXPECT_NEAR(s.x(), 1.0, 0.015);  // heights rounded, ends squared
    EXPECT_NEAR(s.y(), 1.0, 0.015);
  }
  ExpectBands(charts, g, mesh, o.max_stretch, true);
  // One band less than the stack needs: two charts.
  o.max_stack_texels = 8 * 31 - 1;
  EXPECT_EQ(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, o).size(), 2u);
}

// On a sphere every face lands in exactly one strip, strips are bands within
// the stretch bound, and a tighter bound gives shorter strips (more of them).
TEST(Charts, StripsOfASphereAreBandsWithinTheStretchBound) {
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(3, 1.0);  // 1280 faces
  const PatchGeometry g = Geometry(mesh);
  atlas::StripChartOptions o;
  o.texel_size = kTexel;
  std::size_t previous_charts = 0;
  for (const double bound : {1.25, 1.1}) {
    o.max_stretch = bound;
    for (const atlas::StripSide side :
         {atlas::StripSide::kTallest, atlas::StripSide::kNearestPreferred}) {
      o.side = side;
      const auto charts = CheckedStripCharts(mesh, g, o);
      ExpectBands(charts, g, mesh, bound);
      if (side == atlas::StripSide::kTallest) {
        EXPECT_GT(charts.size(), previous_charts);
        previous_charts = charts.size();
      }
    }
  }
  // Stacked: the bands still never overlap and their shared vertices agree.
  o.max_stretch = 1.25;
  o.max_stack_texels = 300;
  atlas::StripChartStats stats;
  const auto charts = CheckedStripCharts(mesh, g, o, &stats);
  EXPECT_GT(stats.stacked, 0);
  ExpectBands(charts, g, mesh, o.max_stretch, true);
}

// Fitted to irregular faces, strips of a jittered sphere stay bands within the
// stretch bound, are fewer (a face the rung's similarity over-stretches takes
// its least-stretching apex instead of ending the band), and their heights
// fall on the ladder preferred * s^k.
TEST(Charts, StripsFittedToIrregularFacesAreFewerAndOnTheHeightLadder) {
  const mesh::TriangleMesh mesh = JitteredIcosphere(11);
  const PatchGeometry g = Geometry(mesh);
  atlas::StripChartOptions o;
  o.texel_size = kTexel;
  const double preferred = atlas::PreferredBandHeight(g.patches, kTexel);
  std::size_t strips[2] = {0, 0};
  std::size_t heights[2] = {0, 0};
  for (const bool fit : {false, true}) {
    o.fit_irregular_faces = fit;
    const auto charts = CheckedStripCharts(mesh, g, o);
    ExpectBands(charts, g, mesh, o.max_stretch);
    std::set<long> band_heights;
    for (const auto& chart : charts) {
      if (chart.size() == 1 && chart[0].linear.isIdentity()) continue;  // a lone face
      double lo = std::numeric_limits<double>::max(), hi = -lo;
      for (const atlas::ChartFace& cf : chart)
        for (const auto& c : g.patches[static_cast<std::size_t>(cf.face)].corners_in_frame) {
          const double y = (cf.linear * c + cf.translation).y() / kTexel;
          lo = std::min(lo, y), hi = std::max(hi, y);
        }
      const long h = std::lround(hi - lo);
      band_heights.insert(h);
      if (fit) {
        const double k = std::log(h / preferred) / std::log(o.max_stretch);
        EXPECT_TRUE(h == std::lround(preferred) ||
                    h == std::lround(preferred * std::pow(o.max_stretch, std::round(k))))
            << "band height " << h << " off the ladder of " << preferred;
      }
    }
    strips[fit] = charts.size();
    heights[fit] = band_heights.size();
  }
  EXPECT_LT(static_cast<double>(strips[1]), 0.9 * static_cast<double>(strips[0]));
  EXPECT_LT(heights[1] * 2, heights[0]) << heights[1] << " heights against " << heights[0];
}

// Stacks of a few bands on a sphere: at most 4 bands of the preferred height
// high, and each stacked band within half a band of the ends of the chain it
// stands on (the top line of the band below), so stacks stay near rectangles.
TEST(Charts, StacksOfFewBandsStayWithinTheirHeightAndOverhang) {
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(4, 1.0);  // 5120 faces
  const PatchGeometry g = Geometry(mesh);
  const double band = atlas::PreferredBandHeight(g.patches, kTexel);
  ASSERT_GT(band, 10.0);
  atlas::StripChartOptions o;
  o.texel_size = kTexel;
  o.max_stack_texels = 4 * band + 0.5;
  o.max_stack_overhang_texels = 0.5 * band;
  atlas::StripChartStats stats;
  const auto charts = CheckedStripCharts(mesh, g, o, &stats);
  EXPECT_GT(stats.stacked, 100);
  ExpectBands(charts, g, mesh, o.max_stretch, true);
  int checked_layers = 0;
  for (const auto& chart : charts) {
    // Per band line (y in 1e-3 texels): the x of the corners of the faces
    // above it and of those below it.
    std::map<long, std::pair<std::vector<double>, std::vector<double>>> on_line;
    for (const atlas::ChartFace& cf : chart) {
      std::array<Eigen::Vector2d, 3> q;
      long lo = std::numeric_limits<long>::max(), hi = std::numeric_limits<long>::min();
      for (std::size_t k = 0; k < 3; ++k) {
        q[k] = (cf.linear * g.patches[static_cast<std::size_t>(cf.face)].corners_in_frame[k] +
                cf.translation) /
               kTexel;
        lo = std::min(lo, std::lround(q[k].y() * 1000));
        hi = std::max(hi, std::lround(q[k].y() * 1000));
      }
      for (const auto& p : q) {
        on_line[lo].first.push_back(p.x());   // a face above line lo
        on_line[hi].second.push_back(p.x());  // a face below line hi
      }
    }
    const double height = (on_line.rbegin()->first - on_line.begin()->first) / 1000.0;
    EXPECT_LE(height, o.max_stack_texels + 0.01);
    for (const auto& [y, xs] : on_line) {
      const auto& [above, below] = xs;
      if (above.empty() || below.empty()) continue;  // the stack's bottom or top line
      // The chain: the corners of the band below on this line.
      double chain_lo = std::numeric_limits<double>::max(), chain_hi = -chain_lo;
      for (std::size_t i = 0; i < below.size(); ++i) {
        chain_lo = std::min(chain_lo, below[i]);
        chain_hi = std::max(chain_hi, below[i]);
      }
      for (const double x : above) {
        EXPECT_GE(x, chain_lo - o.max_stack_overhang_texels - 1e-6);
        EXPECT_LE(x, chain_hi + o.max_stack_overhang_texels + 1e-6);
      }
      ++checked_layers;
    }
  }
  EXPECT_EQ(checked_layers, stats.stacked);
}

// On a torus, bands along the ring lie on circles of different lengths. A
// stacked band's vertices on its free line are placed from the band below, so
// the difference does not add up along the band: the bands above cover the
// ones below, and few faces are left in charts of one band.
TEST(Charts, StackedBandsAlongATorusRingCoverTheBandBelow) {
  const mesh::TriangleMesh mesh = datasets::MakeTorus(96, 40, 0.8, 0.35);  // 7680 faces
  const PatchGeometry g = Geometry(mesh);
  const double band = atlas::PreferredBandHeight(g.patches, kTexel);
  atlas::StripChartOptions o;
  o.texel_size = kTexel;
  o.max_stack_texels = 4 * band + 0.5;
  o.max_stack_overhang_texels = 0.5 * band;
  const auto charts = CheckedStripCharts(mesh, g, o);
  ExpectBands(charts, g, mesh, o.max_stretch, true);
  std::size_t faces_in_single_bands = 0;
  for (const auto& chart : charts) {
    std::set<long> lines;  // y of the corners, in 1e-3 texels
    for (const atlas::ChartFace& cf : chart)
      for (const Eigen::Vector2d& c : g.patches[static_cast<std::size_t>(cf.face)].corners_in_frame)
        lines.insert(std::lround((cf.linear * c + cf.translation).y() / kTexel * 1000));
    if (lines.size() <= 2) faces_in_single_bands += chart.size();
  }
  // With the apex placed from the rung (errors adding up): 2721 faces, 0.35.
  EXPECT_LT(faces_in_single_bands, mesh.faces.size() / 10);
}

// Cylinder caps are fans: each is unfolded rigidly about its centre and cut
// into sectors of at most 90 degrees standing upright on the centre; once the
// mesh is subdivided, the sectors take in the cap's rings of faces.
TEST(Charts, FansOfCylinderCapsAreUprightSectors) {
  constexpr int kAround = 48;
  for (const bool subdivided : {false, true}) {
    mesh::TriangleMesh mesh = datasets::MakeCylinder(kAround, 12, 0.6, 1.6);
    const int first_centre = static_cast<int>(mesh.vertices.size()) - 2;
    if (subdivided) mesh = mesh::SubdivideMidpoint(mesh);
    const PatchGeometry g = Geometry(mesh);
    atlas::StripChartOptions o;
    o.texel_size = kTexel;
    atlas::StripChartStats stats;
    const auto charts = CheckedStripCharts(mesh, g, o, &stats);
    EXPECT_EQ(stats.fans, 2);
    ASSERT_GE(stats.fan_sectors, 8);  // at most 90 degrees each
    std::size_t cap_faces = 0;
    for (std::size_t c = 0; c < static_cast<std::size_t>(stats.fan_sectors); ++c) {
      double y_centre = std::numeric_limits<double>::quiet_NaN();
      double y_min = std::numeric_limits<double>::max();
      std::vector<Eigen::Vector2d> rim;
      for (const atlas::ChartFace& cf : charts[c]) {
        const auto f = static_cast<std::size_t>(cf.face);
        EXPECT_GT(std::abs(g.patches[f].frame.z_axis.z()), 1 - 1e-9) << "a side face in a fan";
        const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
        EXPECT_NEAR(s.x(), 1.0, 1e-6);  // rigid: caps are flat
        EXPECT_NEAR(s.y(), 1.0, 1e-6);
        EXPECT_GT(cf.linear.determinant(), 0.0);
        for (std::size_t k = 0; k < 3; ++k) {
          const Eigen::Vector2d q =
              (cf.linear * g.patches[f].corners_in_frame[k] + cf.translation) / kTexel;
          y_min = std::min(y_min, q.y());
          if (mesh.faces[f][k] >= first_centre && mesh.faces[f][k] < first_centre + 2)
            y_centre = q.y();
          else
            rim.push_back(q);
        }
        ++cap_faces;
      }
      // The centre is the sector's lowest point, on the band's bottom line
      // (a texel centre, less a hair), and the sector opens upwards.
      EXPECT_NEAR(y_centre, 0.5 - 1e-3, 1e-9);
      EXPECT_NEAR(y_min, y_centre, 1e-9);
      for (const Eigen::Vector2d& q : rim) EXPECT_GT(q.y() - y_centre, 0.5 * q.norm() - 1.0);
    }
    EXPECT_EQ(cap_faces, 2u * kAround * (subdivided ? 4u : 1u));
  }
}

/// Bakes the layout's coverage, expecting that a texel written twice is
/// written by faces of one chart only.
atlas::AtlasCoverage ExpectNoTexelInTwoCharts(const atlas::AtlasLayout& layout, int gutter) {
  std::vector<cv::Mat> owner;
  for (const cv::Size& size : layout.atlas_sizes) owner.emplace_back(size, CV_32SC1, -1);
  return atlas::VisitAtlasTexels(
      layout, kTexel, gutter, [&](int atlas, int x, int y, int face, const Eigen::Vector2d&) {
        int& who = owner[static_cast<std::size_t>(atlas)].at<int>(y, x);
        const int chart = layout.faces[static_cast<std::size_t>(face)].chart;
        if (who >= 0) {
          EXPECT_EQ(layout.faces[static_cast<std::size_t>(who)].chart, chart)
              << "texel " << x << ", " << y;
        }
        who = face;
      });
}

// A latitude-longitude sphere's poles are curved fans (their angles sum to
// less than 360 degrees): unfolded about the pole, their sectors keep stretch
// 1, and the strip layout stays valid (no texel in two charts, the stretch
// bound, texture coordinates).
TEST(Charts, CurvedFansOfALatitudeLongitudeSphere) {
  constexpr int kAround = 24, kRings = 12;
  mesh::TriangleMesh mesh;
  mesh.vertices.emplace_back(0.0, 0.0, 1.0);  // north pole
  for (int j = 1; j < kRings; ++j)
    for (int i = 0; i < kAround; ++i) {
      const double theta = kPi * j / kRings, phi = 2 * kPi * i / kAround;
      mesh.vertices.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                 std::cos(theta));
    }
  mesh.vertices.emplace_back(0.0, 0.0, -1.0);  // south pole
  const int south = static_cast<int>(mesh.vertices.size()) - 1;
  auto at = [&](int ring, int i) { return 1 + (ring - 1) * kAround + (i % kAround); };
  for (int i = 0; i < kAround; ++i) {
    mesh.faces.push_back({0, at(1, i), at(1, i + 1)});
    mesh.faces.push_back({south, at(kRings - 1, i + 1), at(kRings - 1, i)});
    for (int j = 1; j + 1 < kRings; ++j) {
      mesh.faces.push_back({at(j, i), at(j + 1, i), at(j + 1, i + 1)});
      mesh.faces.push_back({at(j, i), at(j + 1, i + 1), at(j, i + 1)});
    }
  }
  for (Eigen::Vector3d& v : mesh.vertices) v *= 0.5;  // radius 250 texels
  const PatchGeometry g = Geometry(mesh);
  atlas::StripChartOptions so;
  so.texel_size = kTexel;
  atlas::StripChartStats stats;
  const auto charts = CheckedStripCharts(mesh, g, so, &stats);
  EXPECT_EQ(stats.fans, 2);
  std::size_t pole_faces = 0;
  for (std::size_t c = 0; c < static_cast<std::size_t>(stats.fan_sectors); ++c)
    for (const atlas::ChartFace& cf : charts[c]) {
      const Eigen::Vector2d s = atlas::SingularValues2(cf.linear);
      EXPECT_NEAR(s.x(), 1.0, 1e-6);
      EXPECT_NEAR(s.y(), 1.0, 1e-6);
      ++pole_faces;
    }
  EXPECT_EQ(pole_faces, 2u * kAround);  // curved: nothing beyond the ring
  atlas::AtlasOptions o;
  o.flattening = atlas::ChartFlattening::kStrips;
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
  ExpectNoTexelInTwoCharts(layout, o.gutter);
  const atlas::AtlasStretch stretch = atlas::MeasureStretch(g.patches, layout);
  EXPECT_LE(stretch.max, o.max_chart_stretch + 1e-9);
  EXPECT_GE(stretch.min, 1 / o.max_chart_stretch - 1e-9);
  ExpectLayoutAgreesWithTextureCoordinates(mesh, g, layout);
}

// The default layout (auto) is strips on the demo's sphere, cylinder and torus, fills the
// atlases above 85 % there (bench/atlas_bench measures the rest), never puts
// two charts on one texel, and agrees with the texture coordinates.
class StripLayoutTest : public ::testing::TestWithParam<datasets::SceneShape> {};

TEST_P(StripLayoutTest, FillsAtlasesAboveEightyFivePercent) {
  const datasets::SceneShape shape = GetParam();
  const mesh::TriangleMesh mesh = datasets::CoarseMesh(shape);
  const PatchGeometry g = Geometry(mesh);
  atlas::AtlasOptions o;
  ASSERT_EQ(o.flattening, atlas::ChartFlattening::kAuto);
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
  EXPECT_EQ(layout.flattening, atlas::ChartFlattening::kStrips);
  const atlas::AtlasCoverage coverage = ExpectNoTexelInTwoCharts(layout, o.gutter);
  double texels = 0;
  for (const cv::Size& size : layout.atlas_sizes) texels += size.area();
  EXPECT_GT(static_cast<double>(coverage.inside_texels) / texels, 0.85)
      << datasets::SceneShapeName(shape);
  const atlas::AtlasStretch stretch = atlas::MeasureStretch(g.patches, layout);
  EXPECT_LE(stretch.max, o.max_chart_stretch + 1e-9);
  EXPECT_GE(stretch.min, 1 / o.max_chart_stretch - 1e-9);
  ExpectLayoutAgreesWithTextureCoordinates(mesh, g, layout);
}

// One ctest per shape, so that they spread over the cores.
INSTANTIATE_TEST_SUITE_P(Charts, StripLayoutTest,
                         ::testing::Values(datasets::SceneShape::kSphere,
                                           datasets::SceneShape::kCylinder,
                                           datasets::SceneShape::kTorus));

// On an irregular mesh (vertices moved along the surface by up to a third of
// an edge) strips fragment; auto keeps whichever of strips and rigid charts
// takes fewer atlas texels.
TEST(Charts, AutoKeepsTheSmallerOfStripsAndRigidCharts) {
  const mesh::TriangleMesh mesh = JitteredIcosphere(3);
  const PatchGeometry g = Geometry(mesh);
  atlas::AtlasOptions o;
  std::int64_t texels[3];
  const atlas::ChartFlattening kinds[3] = {atlas::ChartFlattening::kAuto,
                                           atlas::ChartFlattening::kStrips,
                                           atlas::ChartFlattening::kRigid};
  for (int i = 0; i < 3; ++i) {
    o.flattening = kinds[i];
    const atlas::AtlasLayout layout =
        atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
    texels[i] = layout.Texels();
    EXPECT_NE(layout.flattening, atlas::ChartFlattening::kAuto);
  }
  EXPECT_EQ(texels[0], std::min(texels[1], texels[2]));
}

// Strip pieces of equal height are packed in rows by best fit: each place in
// a row takes the piece (of the next few, at either turn) whose end leaves the
// least gap, so slanted ends nest. On an irregular mesh, where strips fragment
// into short bands, this is what lets them fill an atlas better than rigid
// charts (0.69 and below, docs/synth.md).
TEST(Charts, FragmentedStripsOfAnIrregularSphereNestInRows) {
  const mesh::TriangleMesh mesh = JitteredIcosphere(5);
  const PatchGeometry g = Geometry(mesh);
  atlas::AtlasOptions o;
  double occupancy[2] = {0, 0};
  const atlas::ChartFlattening kinds[2] = {atlas::ChartFlattening::kStrips,
                                           atlas::ChartFlattening::kRigid};
  for (int i = 0; i < 2; ++i) {
    o.flattening = kinds[i];
    const atlas::AtlasLayout layout =
        atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
    const atlas::AtlasCoverage coverage = ExpectNoTexelInTwoCharts(layout, o.gutter);
    occupancy[i] =
        static_cast<double>(coverage.inside_texels) / static_cast<double>(layout.Texels());
    if (kinds[i] == atlas::ChartFlattening::kStrips) {
      const atlas::AtlasStretch stretch = atlas::MeasureStretch(g.patches, layout);
      EXPECT_LE(stretch.max, o.max_chart_stretch + 1e-9);
      EXPECT_GE(stretch.min, 1 / o.max_chart_stretch - 1e-9);
      ExpectLayoutAgreesWithTextureCoordinates(mesh, g, layout);
    }
  }
  // Measured with best fit before strips were fitted to irregular faces: strips
  // 0.767, rigid 0.689; strips packed in order were 0.640.
  EXPECT_GT(occupancy[0], 0.72) << "rigid " << occupancy[1];
  EXPECT_GT(occupancy[0], occupancy[1] + 0.03);
}

// A run of parallel slivers (as quadric decimation leaves on flat or
// cylindrical parts), each longer than the chart extent: rigid charts gather
// them into one chart (the seed's box bounds the extent), which packs upright
// into a band a little taller than the run. Slivers 3 texels wide bring
// faces that share no vertex within two gutters of each other; the faces
// between cover the way, so there is no crack and they still join.
TEST(Charts, RigidChartsGatherARunOfSliversLongerThanTheExtent) {
  constexpr int kSlivers = 12;
  for (const int width_texels : {10, 3}) {
    const double length = 800 * kTexel, width = width_texels * kTexel;
    mesh::TriangleMesh mesh;
    // Along a line 30 degrees off the x axis, so the chart lies diagonally in its frame.
    const Eigen::Vector3d along(std::cos(kPi / 6), std::sin(kPi / 6), 0.0);
    const Eigen::Vector3d across(-std::sin(kPi / 6), std::cos(kPi / 6), 0.0);
    for (int i = 0; i <= kSlivers / 2; ++i) {
      mesh.vertices.push_back(i * width * across);
      mesh.vertices.push_back(i * width * across + length * along);
    }
    for (int i = 0; i < kSlivers / 2; ++i) {
      const int a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
      mesh.faces.push_back({a, b, c});
      mesh.faces.push_back({b, d, c});
    }
    const PatchGeometry g = Geometry(mesh);
    atlas::RigidChartOptions ro;
    ro.texel_size = kTexel;
    const auto charts = atlas::MakeRigidCharts(mesh, g.patches, g.unfoldings, ro);
    ExpectEachFaceInOneChart(charts, mesh.faces.size());
    EXPECT_EQ(charts.size(), 1u) << width_texels;
    atlas::AtlasOptions o;
    o.flattening = atlas::ChartFlattening::kRigid;
    const atlas::AtlasLayout layout =
        atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
    ASSERT_EQ(layout.atlas_sizes.size(), 1u);
    // The run's width, a gutter ring each side, a texel of rounding.
    EXPECT_LE(layout.atlas_sizes[0].height, kSlivers / 2 * width_texels + 2 * o.gutter + 2)
        << width_texels;
    ExpectNoTexelInTwoCharts(layout, o.gutter);
  }
}

// Options out of range are refused.
TEST(Charts, BadChartOptionsAreRefused) {
  atlas::AtlasOptions o;
  o.max_chart_stretch = 1.0;
  EXPECT_THROW(o.Check(), OptionError);
  o.max_chart_stretch = 5.0;
  EXPECT_THROW(o.Check(), OptionError);
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(2, 0.5);
  const PatchGeometry g = Geometry(mesh);
  atlas::StripChartOptions strips;
  strips.texel_size = kTexel;
  strips.min_fan_faces = 2;  // a fan needs 3 faces
  EXPECT_THROW(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, strips), OptionError);
  strips.min_fan_faces = 0;  // no fans
  EXPECT_NO_THROW(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, strips));
  strips.max_stack_texels = -1.0;
  EXPECT_THROW(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, strips), OptionError);
  strips.max_stack_texels = 100.0;
  strips.min_stack_cover = 0.0;
  EXPECT_THROW(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, strips), OptionError);
  strips.min_stack_cover = 0.75;
  strips.max_stack_overhang_texels = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, strips), OptionError);
  atlas::RigidChartOptions rigid;
  EXPECT_NO_THROW(rigid.Check());
  rigid.gutter = -1;
  EXPECT_THROW(atlas::MakeRigidCharts(mesh, g.patches, g.unfoldings, rigid), OptionError);
  rigid.gutter = 2;
  rigid.max_normal_angle_deg = 0.0;
  EXPECT_THROW(rigid.Check(), OptionError);
  atlas::ConformalChartOptions conformal;
  EXPECT_NO_THROW(conformal.Check());
  conformal.max_stretch = 1.0;
  EXPECT_THROW(atlas::MakeConformalCharts(mesh, g.patches, g.unfoldings, conformal), OptionError);
}

// Patches and unfoldings that do not belong to the mesh are a programming error.
TEST(Charts, PatchesOfAnotherMeshAreAnInternalError) {
  const mesh::TriangleMesh mesh = datasets::MakeGridPlane(2, 0.5);
  PatchGeometry g = Geometry(mesh);
  g.patches.pop_back();
  atlas::StripChartOptions strips;
  strips.texel_size = kTexel;
  EXPECT_THROW(atlas::MakeStripCharts(mesh, g.patches, g.unfoldings, strips), InternalError);
}

// Every flattening of a small sphere (80 faces, about 8,000 texels) keeps its charts apart,
// its stretch within the bound and its texture coordinates in agreement with the frames: what
// the full-size layouts above check, at a size the sanitizer build (which skips those,
// tests/sanitizer_skip.txt) runs in seconds.
TEST(Charts, EveryFlatteningOfASmallSphereKeepsItsChartsApart) {
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(1, 0.05);
  const PatchGeometry g = Geometry(mesh);
  atlas::AtlasOptions o;
  for (const atlas::ChartFlattening kind :
       {atlas::ChartFlattening::kRigid, atlas::ChartFlattening::kConformal,
        atlas::ChartFlattening::kStrips, atlas::ChartFlattening::kAuto}) {
    o.flattening = kind;
    const atlas::AtlasLayout layout =
        atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, kTexel, o);
    SCOPED_TRACE(atlas::ChartFlatteningName(layout.flattening));
    const atlas::AtlasCoverage coverage = ExpectNoTexelInTwoCharts(layout, o.gutter);
    EXPECT_GT(coverage.inside_texels, 0);
    const atlas::AtlasStretch stretch = atlas::MeasureStretch(g.patches, layout);
    EXPECT_LE(stretch.max, o.max_chart_stretch + 1e-9);
    EXPECT_GE(stretch.min, 1 / o.max_chart_stretch - 1e-9);
    ExpectLayoutAgreesWithTextureCoordinates(mesh, g, layout);
  }
}

}  // namespace
}  // namespace texlume::synth
