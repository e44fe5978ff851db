// Issue 8: per-triangle image-constrained BTF quilting with graph-cut seams,
// the BTF model folder and its rendering, on a small glossy sphere.
#include "pipeline/btf_synth_job.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>

#include "btf/btf.h"
#include "core/errors.h"
#include "datasets_synthetic/scene.h"
#include "model/btf_model.h"
#include "model/model_io.h"
#include "pipeline/render_job.h"
#include "pipeline/synth_job.h"
#include "ptm/fit.h"
#include "ptm/ptm_io.h"
#include "quilt/unseen_fill.h"
#include "render/btf_shading.h"
#include "synth/mesh_btf.h"
#include "tests/test_util.h"

namespace texlume::btf {
namespace {
namespace fs = std::filesystem;

class MeshBtfTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new testing::TempDir;
    datasets::SceneOptions o = datasets::SmallObjectSceneOptions(datasets::SceneShape::kSphere,
                                                                 datasets::MaterialKind::kStone);
    o.material.relief_height = 0.012;
    o.material.specular = 0.5;  // view-dependent: a PTM cannot hold it
    o.capture_size = 96;
    o.write_btf = true;
    o.btf_size = 96;
    o.btf_view_count = 13;
    o.btf_light_count = 24;
    o.write_surface = false;
    o.num_held_out_views = 2;
    o.held_out_lights_per_view = 2;
    datasets::GenerateScene(o, tmp_->path() / "scene");
    sample_ =
        new BtfFactorisation(FactoriseBtf(ReadBtfCapture(tmp_->path() / "scene/material/btf"), 24));
    job_ = new pipeline::SynthJobOptions(Job(tmp_->path() / "btf_model"));
    inputs_ = new pipeline::SynthInputs(pipeline::LoadSynthInputs(*job_));
    pipeline::PrepareSynthMesh(*inputs_, *job_, 96, 0.004, 8);
    synthesis_ = new synth::BtfMeshSynthesis(
        synth::SynthesizeMeshBtf(inputs_->mesh, inputs_->reconstruction, inputs_->visibility,
                                 inputs_->photos, *sample_, Options()));
  }
  static void TearDownTestSuite() {
    delete filled_;
    delete synthesis_;
    delete inputs_;
    delete job_;
    delete sample_;
    delete tmp_;
  }
  static synth::BtfMeshSynthesisOptions Options() {
    synth::BtfMeshSynthesisOptions so;
    so.sample_texel_size = 0.004;
    return so;
  }
  static pipeline::SynthJobOptions Job(const fs::path& out) {
    pipeline::SynthJobOptions j;
    const fs::path object = tmp_->path() / "scene/object";
    j.model_dir = object / "sparse";
    j.images_dir = object / "images";
    j.lights_file = object / "lights.json";
    j.mesh_file = object / "mesh.ply";
    j.out_dir = out;
    j.synthesis.sample_texel_size = 0.004;
    j.atlas.atlas_size = 1024;
    j.write_report = false;
    return j;
  }
  static pipeline::BtfSynthJobOptions BtfJob(const fs::path& out) {
    pipeline::BtfSynthJobOptions o;
    o.job = Job(out);
    o.btf = tmp_->path() / "scene/material/btf";
    o.components = 24;
    o.synthesis = Options();
    return o;
  }
  static pipeline::RenderJobSummary Render(const fs::path& model, const std::string& out,
                                           render::RenderMode mode, bool as_btf) {
    pipeline::RenderJobOptions r;
    const fs::path held = tmp_->path() / "scene/object/held_out";
    r.model_folder = model;
    r.cameras_dir = held / "sparse";
    r.lights_file = held / "lights.json";
    r.out_dir = tmp_->path() / out;
    r.mode = mode;
    r.truth_images_dir = held / "images";
    r.truth_masks_dir = held / "masks";
    r.btf_as_btf = as_btf;
    return pipeline::RunRenderJob(r);
  }
  // The synthesis with --fill-unseen graphcut (quilt/unseen_fill.h) applied,
  // made once for the tests that need it.
  struct FilledSynthesis {
    synth::BtfMeshSynthesis synthesis;
    quilt::UnseenFillSummary fill;
  };
  static const FilledSynthesis& Filled() {
    if (!filled_) {
      filled_ = new FilledSynthesis{*synthesis_, {}};
      quilt::UnseenFillOptions o;
      o.atlas.atlas_size = 1024;
      o.quilt.work_patch_levels = 16;
      filled_->fill =
          quilt::FillUnseenFaces(inputs_->mesh, filled_->synthesis, synth::BtfSample(*sample_), o);
    }
    return *filled_;
  }
  static testing::TempDir* tmp_;
  static FilledSynthesis* filled_;
  static BtfFactorisation* sample_;
  static pipeline::SynthJobOptions* job_;
  static pipeline::SynthInputs* inputs_;
  static synth::BtfMeshSynthesis* synthesis_;
};
testing::TempDir* MeshBtfTest::tmp_ = nullptr;
MeshBtfTest::FilledSynthesis* MeshBtfTest::filled_ = nullptr;
BtfFactorisation* MeshBtfTest::sample_ = nullptr;
pipeline::SynthJobOptions* MeshBtfTest::job_ = nullptr;
pipeline::SynthInputs* MeshBtfTest::inputs_ = nullptr;
synth::BtfMeshSynthesis* MeshBtfTest::synthesis_ = nullptr;

TEST_F(MeshBtfTest, EveryTrianglePatchLiesInTheSampleMostFromThePhotos) {
  const synth::BtfMeshSynthesis& s = *synthesis_;
  ASSERT_EQ(s.patches.size(), 1280u);
  EXPECT_EQ(s.num_from_photos + s.num_from_neighbours + s.num_random, 1280u);
  EXPECT_GT(s.num_from_photos, 1280u * 6 / 10);
  EXPECT_LE(s.num_random, 1u);
  for (const synth::TrianglePatch& p : s.patches) {
    EXPECT_GE(p.sample_x, 0);
    EXPECT_GE(p.sample_y, 0);
    EXPECT_LE(p.sample_x + p.width, sample_->width);
    EXPECT_LE(p.sample_y + p.height, sample_->height);
  }
  // Exposures differ per photo in [0.8, 1.2] x light intensities: gains vary.
  const auto [lo, hi] = std::minmax_element(s.photo_gains.begin(), s.photo_gains.end());
  EXPECT_GT(*lo, 0.4);
  EXPECT_LT(*hi, 2.5);
}

// --fill-unseen graphcut with a BTF sample (quilt/unseen_fill.h): the faces no
// photo placed read the quilt of the geometry maps (in the sample, factors of
// 1, moved off their overlap-only patches); a face the photos placed keeps its
// lookups where no filled face is next to it.
TEST_F(MeshBtfTest, GraphCutFillQuiltsTheUnseenFacesOnTheGeometryMaps) {
  const synth::BtfMeshSynthesis& s = Filled().synthesis;
  const quilt::UnseenFillSummary& fill = Filled().fill;
  EXPECT_EQ(fill.faces, s.num_from_neighbours + s.num_random);
  ASSERT_GT(fill.faces, 0u);
  EXPECT_GT(fill.stats.patches, 1u);
  std::size_t moved = 0, kept = 0;
  for (std::size_t f = 0; f < s.patches.size(); ++f) {
    const synth::TrianglePatch& patch = s.patches[f];
    const Eigen::Vector2d centre =
        (patch.corners_in_frame[0] + patch.corners_in_frame[1] + patch.corners_in_frame[2]) / 3;
    const synth::BtfSampleLookup before = synthesis_->Lookup(static_cast<int>(f), centre);
    const synth::BtfSampleLookup after = s.Lookup(static_cast<int>(f), centre);
    if (fill.filled[f]) {
      EXPECT_EQ(after.source_face, static_cast<int>(f));
      EXPECT_EQ(after.colour_gain, Eigen::Vector3f::Ones());
      EXPECT_GE(after.sample_px.minCoeff(), 0.0);
      EXPECT_LE(after.sample_px.x(), sample_->width);
      EXPECT_LE(after.sample_px.y(), sample_->height);
      moved += (after.sample_px - before.sample_px).norm() > 1.0;
      continue;
    }
    bool next_to_filled = false;
    for (const synth::Unfolding& u : s.unfoldings[f])
      next_to_filled =
          next_to_filled || (u.face >= 0 && fill.filled[static_cast<std::size_t>(u.face)]);
    if (next_to_filled) continue;
    EXPECT_EQ(after.sample_px, before.sample_px) << "face " << f;
    EXPECT_EQ(after.angle_rad, before.angle_rad) << "face " << f;
    ++kept;
  }
  EXPECT_GT(moved, fill.faces / 2);
  EXPECT_GT(kept, s.num_from_photos / 2);
}

TEST_F(MeshBtfTest, GraphCutSeamsCostNoMoreThanTheStraightMeshEdge) {
  const synth::BtfMeshSynthesis& s = *synthesis_;
  EXPECT_EQ(s.seam_edges, 1920u);  // every edge of the closed sphere
  ASSERT_GT(s.edge_cost, 0.0);
  // The straight seam along the mesh edge is one feasible cut: the minimum is
  // never above it (up to the 1e-6 added per link), and here well below.
  EXPECT_LE(s.seam_cost, s.edge_cost + 1e-6 * static_cast<double>(s.seam_links) + 1e-9);
  EXPECT_LT(s.seam_cost, 0.9 * s.edge_cost);
  // Some texels switch to the neighbour's patch; most keep their own.
  std::size_t switched = 0, total = 0;
  for (const cv::Mat& l : s.labels) switched += cv::countNonZero(l), total += l.total();
  RecordProperty("seam_cost", std::to_string(s.seam_cost));
  RecordProperty("edge_cost", std::to_string(s.edge_cost));
  RecordProperty("switched_texels", std::to_string(switched) + " of " + std::to_string(total));
  EXPECT_GT(switched, 0u);
  EXPECT_LT(switched, total / 4);
}

// Points on the shared edges of `mesh`, looked up from either face: where both
// choose the same patch, they must agree on the sample position and on the
// sample-frame direction of a world tangent (the rotation each lookup reports).
// Only the edges `edge_wanted(f, g)` accepts are visited; `compared(f, p, l)`
// sees each point compared (p in f's frame, l its lookup from f). Returns the
// number of points compared.
int CheckEdgeAgreement(
    const synth::BtfMeshSynthesis& s, const mesh::TriangleMesh& mesh,
    const std::function<bool(std::size_t, int)>& edge_wanted,
    const std::function<void(std::size_t, const Eigen::Vector2d&, const synth::BtfSampleLookup&)>&
        compared_point = {}) {
  int compared = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const synth::Unfolding& u = s.unfoldings[f][static_cast<std::size_t>(k)];
      if (u.face < 0 || !edge_wanted(f, u.face)) continue;
      const Eigen::Vector3d a = mesh.Corner(f, k), b = mesh.Corner(f, (k + 1) % 3);
      for (double w : {0.3, 0.5, 0.7}) {
        const Eigen::Vector3d x = a + w * (b - a);
        const auto& ff = s.patches[f].frame;
        const auto& fh = s.patches[static_cast<std::size_t>(u.face)].frame;
        const synth::BtfSampleLookup lf =
            s.Lookup(static_cast<int>(f), ff.PointInFrame(x).head<2>());
        const synth::BtfSampleLookup lh = s.Lookup(u.face, fh.PointInFrame(x).head<2>());
        if (lf.source_face != lh.source_face) continue;
        ++compared;
        if (compared_point) compared_point(f, ff.PointInFrame(x).head<2>(), lf);
        EXPECT_NEAR((lf.sample_px - lh.sample_px).norm(), 0.0, 1e-6) << f << " " << k;
        const Eigen::Vector3d d = (b - a).normalized();
        const Eigen::Vector2d df =
            Eigen::Rotation2Dd(lf.angle_rad) * ff.DirectionInFrame(d).head<2>();
        const Eigen::Vector2d dh =
            Eigen::Rotation2Dd(lh.angle_rad) * fh.DirectionInFrame(d).head<2>();
        EXPECT_NEAR((df - dh).norm(), 0.0, 1e-6) << f << " " << k;
      }
    }
  }
  return compared;
}

TEST_F(MeshBtfTest, BothSidesOfAnEdgeSeeTheSameSampleTexelAndFrame) {
  const int compared =
      CheckEdgeAgreement(*synthesis_, inputs_->mesh, [](std::size_t, int) { return true; });
  RecordProperty("edge_points_compared", compared);
  EXPECT_GT(compared, 1920 * 3 / 2);  // most edge points agree on a source
}

// --fill-unseen graphcut: where a placed face's seam crosses into a filled
// neighbour, the placed face reads the neighbour's quilt, as the neighbour does
// (a filled face reads only its own quilt, so every point compared is a seam
// crossing into it).
TEST_F(MeshBtfTest, SeamsCrossingIntoAFilledFaceReadItsQuilt) {
  const synth::BtfMeshSynthesis& s = Filled().synthesis;
  const quilt::UnseenFillSummary& fill = Filled().fill;
  ASSERT_GT(fill.faces, 0u);
  const auto filled = [&](int f) { return fill.filled[static_cast<std::size_t>(f)] != 0; };
  // Seen from the placed face, a point whose lookup moved off the neighbour's
  // overlap-only patch (what it read before the fill) reads the quilt, not the
  // old patch. Each edge is visited from both faces.
  int from_placed = 0, moved = 0;
  const int compared = CheckEdgeAgreement(
      s, inputs_->mesh,
      [&](std::size_t f, int g) { return filled(static_cast<int>(f)) != filled(g); },
      [&](std::size_t f, const Eigen::Vector2d& p, const synth::BtfSampleLookup& after) {
        if (filled(static_cast<int>(f))) return;
        ++from_placed;
        const synth::BtfSampleLookup before = synthesis_->Lookup(static_cast<int>(f), p);
        moved += (after.sample_px - before.sample_px).norm() > 1.0;
      });
  RecordProperty("edge_points_compared", compared);
  RecordProperty("seen_from_the_placed_face", from_placed);
  RecordProperty("moved_onto_the_quilt", moved);
  EXPECT_GT(from_placed, 10);
  EXPECT_GT(moved, from_placed / 2);
}

TEST_F(MeshBtfTest, ModelFolderHoldsCoordinatesGeometryAtlasesAndAPtmPreview) {
  const fs::path dir = tmp_->path() / "btf_model";
  const pipeline::BtfSynthJobSummary summary = pipeline::RunBtfSynthJob(BtfJob(dir));
  EXPECT_EQ(summary.faces, 1280u);
  const model::TexturedModel model = model::ReadModelFolder(dir);
  const model::BtfModel btf = model::ReadBtfModel(dir, model);
  EXPECT_EQ(btf.sample.Components(), 24);
  ASSERT_EQ(btf.sample_coords.size(), model.atlases.size());
  const nlohmann::json manifest = model::ReadModelManifest(dir);
  ASSERT_EQ(manifest["btf"]["geometry_atlases"].size(), model.atlases.size());
  for (std::size_t a = 0; a < model.atlases.size(); ++a) {
    EXPECT_EQ(manifest["btf"]["geometry_atlases"][a].size(), 6u);  // 24 components, 4 per PNG
    for (const auto& file : manifest["btf"]["geometry_atlases"][a])
      EXPECT_TRUE(fs::exists(dir / file["file"].get<std::string>()));
    // Every texel inside a triangle shows a position inside the sample.
    const cv::Mat& c = btf.sample_coords[a];
    int inside = 0;
    for (std::size_t f = 0; f < model.mesh.faces.size(); ++f) {
      if (model.face_atlas[f] != static_cast<int>(a)) continue;
      const auto& px = model.corner_px[f];
      const Eigen::Vector2f centroid = (px[0] + px[1] + px[2]) / 3.0f;
      const cv::Vec3f v =
          c.at<cv::Vec3f>(static_cast<int>(centroid.y()), static_cast<int>(centroid.x()));
      EXPECT_GE(v[0], 0.0f);
      EXPECT_GE(v[1], 0.0f);
      EXPECT_LE(v[0], sample_->width);
      EXPECT_LE(v[1], sample_->height);
      EXPECT_LE(std::abs(v[2]), std::numbers::pi + 1e-5);
      ++inside;
    }
    EXPECT_GT(inside, 0);
  }
  // Bad input: a PTM model folder is no BTF model; a missing coordinates file.
  fs::remove(dir / "btf_atlas_0.exr");
  EXPECT_THROW(model::ReadBtfModel(dir, model), InputError);
}

// The BTF drawn as a BTF against its own PTM preview, on the glossy material: the
// comparison with PTM models of the same material (with and without their
// photo-consistency pass) is bench/btf_bench.sh's (docs/btf.md).
TEST_F(MeshBtfTest, OnAGlossyMaterialTheBtfModelBeatsItsPtmPreview) {
  const fs::path btf_dir = tmp_->path() / "btf_model_render";
  pipeline::RunBtfSynthJob(BtfJob(btf_dir));
  const auto btf = Render(btf_dir, "r_btf", render::RenderMode::kPtm, true);
  const auto preview = Render(btf_dir, "r_preview", render::RenderMode::kPtm, false);
  ASSERT_EQ(btf.metrics.size(), 4u);
  RecordProperty("psnr_btf", std::to_string(btf.mean_psnr));
  RecordProperty("psnr_preview", std::to_string(preview.mean_psnr));
  std::printf("held-out PSNR: BTF %.2f, its PTM preview %.2f\n", btf.mean_psnr, preview.mean_psnr);
  EXPECT_GT(btf.mean_psnr, preview.mean_psnr + 0.3);
  // The BTF model's files are what render.json says it drew.
  const nlohmann::json record = ReadJsonFile(tmp_->path() / "r_btf/render.json");
  EXPECT_EQ(record["settings"]["mode"], "btf");
}

TEST(MeshBtfOptions, BadValuesAreRefused) {
  synth::BtfMeshSynthesisOptions o;
  EXPECT_THROW(o.Check(), OptionError);  // no texel size
  o.sample_texel_size = 0.01;
  EXPECT_NO_THROW(o.Check());
  o.seam_band = o.strip + 1;
  EXPECT_THROW(o.Check(), OptionError);
  o.seam_band = 0;
  EXPECT_THROW(o.Check(), OptionError);
  o.seam_band = 4;
  o.correction_noise = 0.0;
  EXPECT_THROW(o.Check(), OptionError);
  o.correction_noise = 0.05;
  o.correction_sigma = -1.0;
  EXPECT_THROW(o.Check(), OptionError);
}

TEST_F(MeshBtfTest, PhotoCorrectionBringsThePatchesCloserToThePhotos) {
  const synth::BtfMeshSynthesis& s = *synthesis_;
  RecordProperty("photo_rms_quilted", std::to_string(s.photo_rms_quilted));
  RecordProperty("photo_rms_corrected", std::to_string(s.photo_rms_corrected));
  std::printf("photo RMS (linear): quilted %.4f, corrected %.4f\n", s.photo_rms_quilted,
              s.photo_rms_corrected);
  EXPECT_GT(s.photo_rms_quilted, 0.0);
  EXPECT_LT(s.photo_rms_corrected, 0.8 * s.photo_rms_quilted);
  // Factors exactly on the faces the photos chose, finite and within their clamp.
  for (std::size_t f = 0; f < s.patches.size(); ++f) {
    const bool from_photos = s.patches[f].source == synth::PatchSource::kPhotos;
    EXPECT_EQ(s.colour_gain[f].empty(), !from_photos) << f;
    if (s.colour_gain[f].empty()) continue;
    double lo, hi;
    cv::minMaxLoc(s.colour_gain[f].reshape(1), &lo, &hi);
    EXPECT_GE(lo, 0.2 - 1e-6);
    EXPECT_LE(hi, 5.0 + 1e-6);
  }
  // Without the pass, every factor is 1 and the residual is the quilted one.
  synth::BtfMeshSynthesisOptions off = Options();
  off.photo_correction = false;
  const synth::BtfMeshSynthesis plain = synth::SynthesizeMeshBtf(
      inputs_->mesh, inputs_->reconstruction, inputs_->visibility, inputs_->photos, *sample_, off);
  const Eigen::Vector2d p = plain.patches[0].corners_in_frame[0] * 0.5;
  EXPECT_EQ(plain.Lookup(0, p).colour_gain, Eigen::Vector3f::Ones());
  EXPECT_EQ(plain.photo_rms_corrected, 0.0);
}

// Frames turned to the photos (synth/tangent_field.h) in the BTF synthesis: on
// this stone, an isotropic sample, auto keeps the first-edge frames; asked
// for, the frames turn, and the patches still come from the photos, inside the
// sample, and agree with the photos about as well.
TEST_F(MeshBtfTest, FramesTurnToThePhotosWhenTheSampleIsDirectionalOrWhenAsked) {
  const synth::BtfMeshSynthesis& s = *synthesis_;
  EXPECT_EQ(s.tangent_frame, synth::TangentFrame::kFirstEdge);
  EXPECT_GE(s.sample_coherence, 0.0);
  EXPECT_LT(s.sample_coherence, synth::kAnisotropicSampleCoherence);
  synth::BtfMeshSynthesisOptions photos = Options();
  photos.tangent_frame = synth::TangentFrame::kPhotos;
  const synth::BtfMeshSynthesis turned =
      synth::SynthesizeMeshBtf(inputs_->mesh, inputs_->reconstruction, inputs_->visibility,
                               inputs_->photos, *sample_, photos);
  EXPECT_EQ(turned.tangent_frame, synth::TangentFrame::kPhotos);
  std::size_t turned_faces = 0;
  for (std::size_t f = 0; f < s.patches.size(); ++f) {
    const synth::TrianglePatch& p = turned.patches[f];
    turned_faces += p.frame.x_axis.dot(s.patches[f].frame.x_axis) < 0.99;
    EXPECT_NEAR(p.frame.z_axis.dot(s.patches[f].frame.z_axis), 1.0, 1e-9);
    EXPECT_GE(p.sample_x, 0);
    EXPECT_GE(p.sample_y, 0);
    EXPECT_LE(p.sample_x + p.width, sample_->width);
    EXPECT_LE(p.sample_y + p.height, sample_->height);
  }
  std::printf("turned %zu of %zu frames; photo RMS quilted %.4f (first edge %.4f)\n", turned_faces,
              s.patches.size(), turned.photo_rms_quilted, s.photo_rms_quilted);
  EXPECT_GT(turned_faces, s.patches.size() / 2);
  EXPECT_GT(turned.num_from_photos, s.num_from_photos * 98 / 100);
  EXPECT_LT(turned.photo_rms_quilted, 1.1 * s.photo_rms_quilted);
}

}  // namespace
}  // namespace texlume::btf
