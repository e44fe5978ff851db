#include "quilt/surface_quilting.h"

#include <gtest/gtest.h>

#include <numbers>
#include <opencv2/imgproc.hpp>
#include <set>

#include "core/errors.h"
#include "datasets_synthetic/material.h"
#include "datasets_synthetic/shapes.h"
#include "quilt/quilt_atlases.h"
#include "synth/btf_sample.h"
#include "tests/quilt/lit_samples.h"

namespace texlume::quilt {
namespace {

struct Surface {
  synth::PatchGeometry geometry;
  atlas::AtlasLayout layout;
  DenseSurface dense;
};

Surface MakeSurface(const mesh::TriangleMesh& mesh, double texel, atlas::AtlasMode mode) {
  Surface s;
  s.geometry = synth::MakePatchGeometry(mesh, texel, 4, synth::TangentFrame::kFirstEdge,
                                        Eigen::Vector3d::UnitZ());
  atlas::AtlasOptions o;
  o.mode = mode;
  o.flattening = atlas::ChartFlattening::kRigid;
  o.atlas_size = 512;
  s.layout = atlas::LayoutAtlases(mesh, s.geometry.patches, s.geometry.unfoldings, texel, o);
  s.dense = DenseSurface::Build(mesh, s.layout, s.geometry.patches, s.geometry.unfoldings, texel);
  return s;
}

// Over the links, how much the two samples' distance in the sample differs
// from their distance on the surface (texels): 0 where the texture runs on
// without a seam or a stretch.
double MeanLookupGap(const Surface& s, const QuiltResult& r, bool across_charts) {
  double sum = 0;
  int count = 0;
  for (std::size_t a = 0; a < s.dense.size(); ++a)
    for (const int b : s.dense.Neighbours(static_cast<int>(a))) {
      const auto bi = static_cast<std::size_t>(b);
      const bool crosses = s.dense.samples()[a].chart != s.dense.samples()[bi].chart;
      if (crosses != across_charts || bi < a) continue;
      const double in_sample =
          (r.lookups[a].sample_px - r.lookups[bi].sample_px).cast<double>().norm();
      const double on_surface =
          (s.dense.PointInWorld(static_cast<int>(a)) - s.dense.PointInWorld(b)).norm() /
          s.dense.texel_size();
      sum += std::abs(in_sample - on_surface);
      ++count;
    }
  return count ? sum / count : 0.0;
}

// Over the links inside charts, how far the step in the sample differs from
// the atlas step turned back by the lookup's angle (texels): 0 where the
// lookups map the atlas onto the sample rigidly, the right way round.
double MeanStepError(const Surface& s, const QuiltResult& r) {
  double sum = 0;
  int count = 0;
  for (std::size_t a = 0; a < s.dense.size(); ++a)
    for (const int b : s.dense.Neighbours(static_cast<int>(a))) {
      const auto bi = static_cast<std::size_t>(b);
      const DenseSample &da = s.dense.samples()[a], &db = s.dense.samples()[bi];
      if (da.chart != db.chart) continue;
      const double angle = r.lookups[a].angle_rad, c = std::cos(angle), sn = std::sin(angle);
      const Eigen::Vector2d step(db.x - da.x, db.y - da.y);  // atlas pixels, rows down
      const Eigen::Vector2d expected(c * step.x() - sn * step.y(), sn * step.x() + c * step.y());
      sum += ((r.lookups[bi].sample_px - r.lookups[a].sample_px).cast<double>() - expected).norm();
      ++count;
    }
  return count ? sum / count : 0.0;
}

// One work patch large enough for the whole plane copies the sample onto it in
// one piece: every sample synthesised, neighbours one texel apart in the sample.
TEST(QuiltSurface, OnePatchCopiesTheSampleInOnePiece) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(64, 1);
  const synth::PtmSample sample(ptm);
  const Surface s = MakeSurface(datasets::MakeGridPlane(2, 0.3), 0.01, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.work_patch_levels = 64;
  const QuiltResult r = QuiltSurface(s.dense, s.layout, sample, o);
  EXPECT_EQ(r.stats.patches, 1u);
  EXPECT_LT(MeanStepError(s, r), 1e-4);
  for (const SampleLookup& l : r.lookups) {
    ASSERT_TRUE(l.synthesised);
    EXPECT_GE(l.sample_px.x(), 0.0f);
    EXPECT_LE(l.sample_px.x(), 64.0f);
  }
  EXPECT_LT(MeanLookupGap(s, r, false), 1e-4);
}

// Per-triangle boxes make every face a chart: one patch still runs across
// their borders as across texels inside them, whether its work image is the
// conformal map of its faces (the paper) or the charts' rigid maps chained.
TEST(QuiltSurface, OnePatchRunsOnAcrossChartBorders) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(64, 2);
  const synth::PtmSample sample(ptm);
  const Surface s =
      MakeSurface(datasets::MakeGridPlane(2, 0.3), 0.01, atlas::AtlasMode::kPerTriangle);
  ASSERT_GT(s.dense.chart_seam_links(), 0u);
  for (const bool conformal : {true, false}) {
    QuiltOptions o;
    o.work_patch_levels = 64;
    o.conformal_work_images = conformal;
    const QuiltResult r = QuiltSurface(s.dense, s.layout, sample, o);
    EXPECT_EQ(r.stats.patches, 1u);
    EXPECT_LT(MeanLookupGap(s, r, false), 1e-4) << conformal;
    EXPECT_LT(MeanLookupGap(s, r, true), 1e-4) << conformal;
    EXPECT_LT(MeanStepError(s, r), 1e-4) << conformal;
  }
}

// Small patches on a closed surface: everything synthesised, by many patches
// whose seams cost less than cuts between unrelated texels; the same seed
// gives the same result.
TEST(QuiltSurface, SmallPatchesCoverAClosedSurfaceDeterministically) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(64, 3);
  const synth::PtmSample sample(ptm);
  const Surface s = MakeSurface(datasets::MakeIcosphere(1, 0.25), 0.02, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.work_patch_levels = 5;
  const QuiltResult a = QuiltSurface(s.dense, s.layout, sample, o);
  const QuiltResult b = QuiltSurface(s.dense, s.layout, sample, o);
  EXPECT_GT(a.stats.patches, 5u);
  for (std::size_t i = 0; i < a.lookups.size(); ++i) {
    ASSERT_TRUE(a.lookups[i].synthesised);
    ASSERT_EQ(a.lookups[i].sample_px, b.lookups[i].sample_px);
  }
  ASSERT_GT(a.stats.cut_links, 0u);
  EXPECT_LT(a.stats.seam_cost / a.stats.cut_links, a.stats.random_pair_cost);
}

// With a field, each patch turns the sample's x axis along it (to the nearest
// of the 72 rotations, 5 degrees apart).
TEST(QuiltSurface, TurnsTheSampleAlongTheField) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(64, 5);
  const synth::PtmSample sample(ptm);
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(2, 0.3);
  const Surface s = MakeSurface(plane, 0.01, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.work_patch_levels = 8;
  const Eigen::Vector3d along(std::cos(1.0), std::sin(1.0), 0.0);  // 57.3 degrees
  o.field_in_world.assign(plane.faces.size(), along);
  const QuiltResult r = QuiltSurface(s.dense, s.layout, sample, o);
  ASSERT_GT(r.stats.patches, 3u);
  for (std::size_t i = 0; i < s.dense.size(); ++i) {
    const DenseSample& d = s.dense.samples()[i];
    // The field's angle in the sample's atlas frame.
    const mesh::TriangleFrame& frame = s.dense.FrameOf(d.face);
    const double a = s.layout.faces[static_cast<std::size_t>(d.face)].AtlasFrameAngle();
    const Eigen::Vector3d x = std::cos(a) * frame.x_axis + std::sin(a) * frame.y_axis;
    const double field = std::atan2(along.dot(frame.z_axis.cross(x)), along.dot(x));
    const double off = std::remainder(r.lookups[i].angle_rad - field, 2 * std::numbers::pi);
    EXPECT_LT(std::abs(off), 2.5 * std::numbers::pi / 180 + 1e-6) << "sample " << i;
  }
}

// A mesh of two components, one of them non-manifold (two planes crossing, four
// faces on each edge of the line): every sample is synthesised, by several
// patches linked across chart borders.
TEST(QuiltSurface, CoversDisconnectedAndNonManifoldMeshes) {
  const ptm::Ptm smooth = datasets::SmoothRandomPtm(96, 5);
  const synth::PtmSample sample(smooth);
  mesh::TriangleMesh crossed = datasets::MakeCrossedPlanes(4, 0.3);
  mesh::TriangleMesh sphere = datasets::MakeIcosphere(2, 0.15);
  for (Eigen::Vector3d& v : sphere.vertices) v.x() += 0.5;
  const Surface s =
      MakeSurface(datasets::JoinMeshes(crossed, sphere), 0.02, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.work_patch_levels = 8;
  const QuiltResult r = QuiltSurface(s.dense, s.layout, sample, o);
  ASSERT_EQ(r.lookups.size(), s.dense.size());
  for (const SampleLookup& l : r.lookups) EXPECT_TRUE(l.synthesised);
  EXPECT_GT(s.dense.chart_seam_links(), 0u);
  EXPECT_GT(r.stats.patches, 2u);
}

TEST(QuiltSurface, RefusesASampleSmallerThanTheSmallestPatch) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(16, 4);  // copies of 11 texels
  const synth::PtmSample sample(ptm);
  const Surface s = MakeSurface(datasets::MakeGridPlane(1, 0.1), 0.01, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.min_work_patch_levels = 6;
  o.work_patch_levels = 8;
  EXPECT_THROW(QuiltSurface(s.dense, s.layout, sample, o), InputError);
}

// The baked atlas turns each texel's light response with its lookup: a sample
// lit most from its +x is, in the atlas, lit most from the direction the
// sample's x axis takes there.
TEST(BakeQuiltedAtlases, TurnsTheLightResponseWithTheLookup) {
  const ptm::Ptm lit = testing::LitFromPlusX(64);
  const synth::PtmSample sample(lit);
  const Surface s = MakeSurface(datasets::MakeGridPlane(2, 0.3), 0.01, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.work_patch_levels = 8;
  o.random_orientation = true;
  const QuiltResult r = QuiltSurface(s.dense, s.layout, sample, o);
  const atlas::Atlases atlases =
      BakeQuiltedAtlases(s.dense, r, s.layout, s.geometry.patches, sample, 2);
  ASSERT_EQ(atlases.ptms.size(), 1u);
  std::set<int> angles;
  for (std::size_t i = 0; i < s.dense.size(); ++i) {
    const DenseSample& d = s.dense.samples()[i];
    const ptm::Ptm& atlas = atlases.ptms[static_cast<std::size_t>(d.atlas)];
    const float* a = atlas.Coefficients(static_cast<std::size_t>(d.y) * atlas.width + d.x);
    const double angle = r.lookups[i].angle_rad;
    EXPECT_NEAR(a[3], 0.4 * std::cos(angle), 1e-4);
    EXPECT_NEAR(a[4], 0.4 * std::sin(angle), 1e-4);
    angles.insert(static_cast<int>(std::lround(angle * 100)));
  }
  EXPECT_GT(angles.size(), 2u);  // several patches, turned differently
}

// A BTF of one component lit most from its +x: the quilted BTF atlases hold
// each dense sample's lookup (position, and the atlas frame's turn into the
// sample's, the reverse of the sample's turn), and their PTM preview is lit
// most from the direction the sample's x axis takes in the atlas, as the PTM
// bake above.
TEST(BakeQuiltedBtfAtlases, HoldsTheLookupAndTurnsTheLightWithIt) {
  const btf::BtfFactorisation lit = testing::LitBtfFromPlusX(64);
  const synth::BtfSample sample(lit);
  const Surface s = MakeSurface(datasets::MakeGridPlane(2, 0.3), 0.01, atlas::AtlasMode::kCharts);
  QuiltOptions o;
  o.work_patch_levels = 8;
  o.random_orientation = true;
  const QuiltResult r = QuiltSurface(s.dense, s.layout, sample, o);
  const atlas::BtfAtlases atlases = BakeQuiltedBtfAtlases(s.dense, r, s.layout, lit, 2);
  ASSERT_EQ(atlases.sample_coords.size(), 1u);
  const std::vector<ptm::Ptm> preview = atlas::PreviewPtms(atlases, lit);
  std::set<int> angles;
  for (std::size_t i = 0; i < s.dense.size(); ++i) {
    const DenseSample& d = s.dense.samples()[i];
    const cv::Vec3f c = atlases.sample_coords[0].at<cv::Vec3f>(d.y, d.x);
    EXPECT_NEAR(c[0], r.lookups[i].sample_px.x(), 1e-4);
    EXPECT_NEAR(c[1], r.lookups[i].sample_px.y(), 1e-4);
    const double angle = r.lookups[i].angle_rad;
    EXPECT_NEAR(std::remainder(c[2] + angle, 2 * std::numbers::pi), 0.0, 1e-4);
    const float* a =
        preview[0].Coefficients(static_cast<std::size_t>(d.y) * preview[0].width + d.x);
    EXPECT_NEAR(std::remainder(std::atan2(a[4], a[3]) - angle, 2 * std::numbers::pi), 0.0, 0.02);
    angles.insert(static_cast<int>(std::lround(angle * 100)));
  }
  EXPECT_GT(angles.size(), 2u);  // several patches, turned differently
}

}  // namespace
}  // namespace texlume::quilt
