#include "quilt/unseen_fill.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "datasets_synthetic/material.h"
#include "datasets_synthetic/shapes.h"
#include "ptm/coefficient_space.h"
#include "synth/btf_sample.h"
#include "synth/mesh_btf.h"
#include "synth/planar_synthesis.h"
#include "tests/quilt/lit_samples.h"

namespace texlume::quilt {
namespace {

using testing::LitFromPlusX;

Eigen::Vector3d FaceCentre(const mesh::TriangleMesh& mesh, std::size_t f) {
  const auto& face = mesh.faces[f];
  return (mesh.vertices[face[0]] + mesh.vertices[face[1]] + mesh.vertices[face[2]]) / 3.0;
}

// A per-triangle synthesis without photos: every patch at the sample's corner
// in its face frame, the faces on the +x side "placed from photos", the others
// by their neighbours.
synth::MeshSynthesis HalfFromPhotos(const mesh::TriangleMesh& mesh, const ptm::Ptm& ptm,
                                    double texel, synth::TangentFrame frame) {
  synth::MeshSynthesis s;
  synth::PatchGeometry g =
      synth::MakePatchGeometry(mesh, texel, 4, frame, Eigen::Vector3d::UnitZ());
  s.patches = std::move(g.patches);
  s.unfoldings = std::move(g.unfoldings);
  s.texel_size = texel;
  s.format = ptm.format;
  s.sample_planes = synth::ToOrthonormalPlanes(ptm);
  for (std::size_t f = 0; f < s.patches.size(); ++f) {
    s.patches[f].source =
        FaceCentre(mesh, f).x() > 0 ? synth::PatchSource::kPhotos : synth::PatchSource::kNeighbours;
  }
  return s;
}

// Rigid charts: the quickest to lay out.
atlas::AtlasOptions Charts() {
  atlas::AtlasOptions o;
  o.atlas_size = 512;
  o.blend_strip = 2;
  o.flattening = atlas::ChartFlattening::kRigid;
  return o;
}

// The features given to the quilt for the faces the photos placed are what the
// main job's atlases hold there (atlas::BuildAtlases turns the face frame into
// the atlas frame on its own): away from the blended edges, equal.
TEST(SamplesOfPhotoFaces, HoldWhatTheAtlasesBakeThere) {
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(2, 1.0);
  const ptm::Ptm lit = LitFromPlusX(64);
  const synth::MeshSynthesis s = HalfFromPhotos(mesh, lit, 0.02, synth::TangentFrame::kFirstEdge);
  const atlas::AtlasOptions o = Charts();
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, s.patches, s.unfoldings, 0.02, o);
  const DenseSurface surface = DenseSurface::Build(mesh, layout, s.patches, s.unfoldings, 0.02);
  const GivenSamples given = SamplesOfPhotoFaces(surface, layout, s);
  const atlas::Atlases atlases = atlas::BuildAtlases(mesh, s, o);
  std::vector<std::vector<cv::Mat>> orthonormal;
  for (const ptm::Ptm& p : atlases.ptms) orthonormal.push_back(synth::ToOrthonormalPlanes(p));
  std::size_t compared = 0;
  for (std::size_t i = 0; i < surface.size(); ++i) {
    const DenseSample& d = surface.samples()[i];
    const synth::TrianglePatch& patch = s.patches[static_cast<std::size_t>(d.face)];
    ASSERT_EQ(given.given[i], patch.source == synth::PatchSource::kPhotos);
    if (!given.given[i]) continue;
    double edge = 1e9;
    for (int k = 0; k < 3; ++k)
      edge = std::min(edge,
                      mesh::DistanceToSegment(patch.corners_in_frame[k],
                                              patch.corners_in_frame[(k + 1) % 3], d.p_in_frame));
    if (edge < 2 * 0.02) continue;  // blended with the neighbour
    for (int m = 0; m < 6; ++m)
      EXPECT_NEAR(given.features[i * 6 + m],
                  orthonormal[static_cast<std::size_t>(d.atlas)][m].at<float>(d.y, d.x), 1e-4);
    ++compared;
  }
  EXPECT_GT(compared, 500u);
}

// The fill shows the quilted sample turned with each face's frame: a sample
// lit from +x, quilted along the face frames' x axes (the cylinder's axis on
// every face), is lit from +x in every filled face's frame (within the 5
// degrees between the 72 rotations), as the face's own patch is, however its
// chart lies in the atlas; the faces the photos placed keep their patches.
TEST(FillUnseenFaces, TurnsTheQuiltIntoEachFaceFrame) {
  const mesh::TriangleMesh mesh = datasets::MakeCylinder(24, 4, 0.5, 1.0);
  const ptm::Ptm lit = LitFromPlusX(64);
  synth::MeshSynthesis s = HalfFromPhotos(mesh, lit, 0.02, synth::TangentFrame::kSmoothField);
  const synth::MeshSynthesis patches_only = s;
  UnseenFillOptions o;
  o.atlas = Charts();
  o.quilt.work_patch_levels = 8;
  const atlas::AtlasLayout layout =
      atlas::LayoutAtlases(mesh, s.patches, s.unfoldings, 0.02, o.atlas);
  std::size_t turned = 0;  // charts laid at an angle to their faces' frames
  for (const atlas::FacePlacement& fp : layout.faces)
    turned += std::abs(std::remainder(fp.AtlasFrameAngle(), 2 * std::numbers::pi)) > 0.2;
  ASSERT_GT(turned, 10u);
  const UnseenFillSummary summary = FillUnseenFaces(mesh, s, o);
  std::size_t unseen = 0;
  for (const synth::TrianglePatch& p : s.patches) unseen += p.source != synth::PatchSource::kPhotos;
  EXPECT_EQ(summary.faces, unseen);
  EXPECT_GT(summary.samples, 1000u);
  EXPECT_GT(summary.given_samples, 1000u);
  EXPECT_GT(summary.stats.patches, 1u);
  for (std::size_t f = 0; f < s.patches.size(); ++f) {
    const synth::TrianglePatch& patch = s.patches[f];
    const Eigen::Vector2d centre =
        (patch.corners_in_frame[0] + patch.corners_in_frame[1] + patch.corners_in_frame[2]) / 3;
    std::array<float, 9> filled{}, own{};
    ASSERT_TRUE(s.SamplePatch(static_cast<int>(f), centre, filled.data()));
    ASSERT_TRUE(patches_only.SamplePatch(static_cast<int>(f), centre, own.data()));
    // Near the caps, work patches also hold cap faces, whose field turns round.
    if (std::abs(patch.frame.z_axis.z()) > 0.5 || std::abs(FaceCentre(mesh, f).z()) > 0.2) continue;
    // A turn of the 5 degrees between two of the 72 rotations, at most.
    const Eigen::Matrix<double, 6, 1> own_coefficients =
        Eigen::Map<const Eigen::Matrix<float, 6, 1>>(own.data()).cast<double>();
    const double five_degrees =
        (ptm::OrthonormalFrameRotation(5 * std::numbers::pi / 180) * own_coefficients -
         own_coefficients)
            .cwiseAbs()
            .maxCoeff();
    const double tolerance = patch.source == synth::PatchSource::kPhotos ? 1e-6 : five_degrees;
    for (int m = 0; m < 6; ++m) EXPECT_NEAR(filled[m], own[m], tolerance) << "face " << f;
  }
}

// The BTF fill turns the same way: a BTF quilted along the face frames' x axes
// (the cylinder's axis) on faces whose charts lie at angles to them reads, in
// every filled face, the sample turned by no more than the 5 degrees between
// the 72 rotations from the face frame; the placed faces read their patches.
TEST(FillUnseenFaces, TurnsTheBtfQuiltIntoEachFaceFrame) {
  const mesh::TriangleMesh mesh = datasets::MakeCylinder(24, 4, 0.5, 1.0);
  const btf::BtfFactorisation lit = testing::LitBtfFromPlusX(64);
  synth::BtfMeshSynthesis s;
  synth::PatchGeometry g = synth::MakePatchGeometry(
      mesh, 0.02, 4, synth::TangentFrame::kSmoothField, Eigen::Vector3d::UnitZ());
  s.patches = std::move(g.patches);
  s.unfoldings = std::move(g.unfoldings);
  s.texel_size = 0.02;
  s.labels.resize(s.patches.size());  // no seams
  for (std::size_t f = 0; f < s.patches.size(); ++f)
    s.patches[f].source =
        FaceCentre(mesh, f).x() > 0 ? synth::PatchSource::kPhotos : synth::PatchSource::kNeighbours;
  const synth::BtfMeshSynthesis patches_only = s;
  UnseenFillOptions o;
  o.atlas = Charts();
  o.quilt.work_patch_levels = 8;
  const UnseenFillSummary summary = FillUnseenFaces(mesh, s, synth::BtfSample(lit), o);
  EXPECT_GT(summary.faces, 10u);
  std::size_t checked = 0;
  for (std::size_t f = 0; f < s.patches.size(); ++f) {
    const synth::TrianglePatch& patch = s.patches[f];
    if (std::abs(patch.frame.z_axis.z()) > 0.5 || std::abs(FaceCentre(mesh, f).z()) > 0.2) continue;
    const Eigen::Vector2d centre =
        (patch.corners_in_frame[0] + patch.corners_in_frame[1] + patch.corners_in_frame[2]) / 3;
    const synth::BtfSampleLookup look = s.Lookup(static_cast<int>(f), centre);
    if (patch.source == synth::PatchSource::kPhotos) {
      EXPECT_EQ(look.sample_px, patches_only.Lookup(static_cast<int>(f), centre).sample_px);
      continue;
    }
    EXPECT_LT(std::abs(std::remainder(look.angle_rad, 2 * std::numbers::pi)), 0.06) << "face " << f;
    ++checked;
  }
  EXPECT_GT(checked, 5u);
}

// Given samples keep their texture, and the quilt grows out from them: given
// half of a one-patch copy of the sample over a plane, one large patch finds
// the same copy and continues it over the other half.
TEST(QuiltSurface, GivenSamplesAreKeptAndContinued) {
  const ptm::Ptm ptm = datasets::SmoothRandomPtm(64, 5);
  const synth::PtmSample sample(ptm);
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(2, 0.3);
  const synth::PatchGeometry g = synth::MakePatchGeometry(
      plane, 0.01, 4, synth::TangentFrame::kSmoothField, Eigen::Vector3d::UnitX());
  atlas::AtlasOptions ao;
  ao.mode = atlas::AtlasMode::kPerTriangle;
  ao.atlas_size = 512;
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(plane, g.patches, g.unfoldings, 0.01, ao);
  const DenseSurface surface = DenseSurface::Build(plane, layout, g.patches, g.unfoldings, 0.01);
  QuiltOptions o;
  o.work_patch_levels = 64;
  const QuiltResult copy = QuiltSurface(surface, layout, sample, o);
  ASSERT_EQ(copy.stats.patches, 1u);
  // The copy's features on the half x < 0, in each sample's chart frame.
  GivenSamples given;
  given.given.assign(surface.size(), false);
  given.features.assign(surface.size() * 6, 0.0f);
  for (std::size_t i = 0; i < surface.size(); ++i) {
    if (surface.PointInWorld(static_cast<int>(i)).x() >= 0) continue;
    given.given[i] = true;
    const SampleLookup& l = copy.lookups[i];
    std::array<float, 6> f{};
    sample.FeaturesAt(l.sample_px.cast<double>(), f.data());
    const Eigen::Matrix<double, 6, 1> turned =
        ptm::OrthonormalFrameRotation(-l.angle_rad) *
        Eigen::Map<const Eigen::Matrix<float, 6, 1>>(f.data()).cast<double>();
    for (int m = 0; m < 6; ++m) given.features[i * 6 + m] = static_cast<float>(turned[m]);
  }
  o.seed = 7;
  const QuiltResult r = QuiltSurface(surface, layout, sample, o, {}, &given);
  EXPECT_GT(r.stats.given, surface.size() / 3);
  EXPECT_EQ(r.stats.patches, 1u);
  std::size_t continued = 0, quilted = 0;
  for (std::size_t i = 0; i < surface.size(); ++i) {
    if (given.given[i]) {
      EXPECT_FALSE(r.lookups[i].synthesised);  // kept: not the quilt's
      continue;
    }
    ASSERT_TRUE(r.lookups[i].synthesised);
    ++quilted;
    continued += (r.lookups[i].sample_px - copy.lookups[i].sample_px).norm() < 0.5f &&
                 std::abs(r.lookups[i].angle_rad - copy.lookups[i].angle_rad) < 1e-3f;
  }
  EXPECT_GT(quilted, 0u);
  EXPECT_EQ(continued, quilted);
}

}  // namespace
}  // namespace texlume::quilt
