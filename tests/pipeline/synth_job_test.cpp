// The main job (issue 6): per-triangle synthesis, blending, atlases, export,
// rendering, on a small synthetic sphere with ground truth.
#include "pipeline/synth_job.h"

#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cstring>
#include <fstream>
#include <functional>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "atlas/atlas.h"
#include "core/errors.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "datasets_synthetic/scene.h"
#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"
#include "model/baselines.h"
#include "model/model_io.h"
#include "model/web_model.h"
#include "pipeline/quilt_job.h"
#include "pipeline/render_job.h"
#include "pipeline/report_pictures.h"
#include "ptm/coefficient_space.h"
#include "ptm/fit.h"
#include "ptm/ptm_io.h"
#include "render/model_render.h"
#include "report/report.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"
#include "synth/mesh_synthesis.h"
#include "tests/test_util.h"

namespace texlume::synth {
namespace {
namespace fs = std::filesystem;

class MeshPipelineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new testing::TempDir;
    datasets::SceneOptions o = datasets::SmallObjectSceneOptions(datasets::SceneShape::kSphere,
                                                                 datasets::MaterialKind::kStone);
    o.material.relief_height = 0.012;
    o.num_held_out_views = 2;
    o.held_out_lights_per_view = 2;
    o.held_out_scale = 2;
    datasets::GenerateScene(o, tmp_->path() / "scene");
    ptm::WritePtmExr(datasets::FitSceneSample(tmp_->path() / "scene"), tmp_->path() / "sample.exr");
    job_ = new pipeline::SynthJobOptions(Job(tmp_->path() / "model"));
    const int threads = omp_get_max_threads();
    omp_set_num_threads(2);  // OutputsAreTheSameOnOneThreadAndOnTwo compares with one
    summary_ = new pipeline::SynthJobSummary(pipeline::RunSynthJob(*job_));
    omp_set_num_threads(threads);
  }
  static void TearDownTestSuite() {
    delete summary_;
    delete job_;
    delete tmp_;
  }
  static pipeline::SynthJobOptions Job(const fs::path& out) {
    pipeline::SynthJobOptions j;
    const fs::path object = tmp_->path() / "scene/object";
    j.model_dir = object / "sparse";
    j.images_dir = object / "images";
    j.lights_file = object / "lights.json";
    j.mesh_file = object / "mesh.ply";
    j.sample_file = tmp_->path() / "sample.exr";
    j.out_dir = out;
    j.synthesis.sample_texel_size = 0.004;
    j.mm_per_world_unit = 1000.0;  // --world-unit 1m
    j.atlas.atlas_size = 1024;
    return j;
  }
  static pipeline::RenderJobSummary Render(render::RenderMode mode, const std::string& out,
                                           const std::string& model = "model") {
    pipeline::RenderJobOptions r;
    const fs::path held = tmp_->path() / "scene/object/held_out";
    r.model_folder = tmp_->path() / model;
    r.cameras_dir = held / "sparse";
    r.lights_file = held / "lights.json";
    r.out_dir = tmp_->path() / out;
    r.mode = mode;
    r.truth_images_dir = held / "images";
    r.truth_masks_dir = held / "masks";
    return pipeline::RunRenderJob(r);
  }
  static testing::TempDir* tmp_;
  static pipeline::SynthJobOptions* job_;
  static pipeline::SynthJobSummary* summary_;
};
testing::TempDir* MeshPipelineTest::tmp_ = nullptr;
pipeline::SynthJobOptions* MeshPipelineTest::job_ = nullptr;
pipeline::SynthJobSummary* MeshPipelineTest::summary_ = nullptr;

TEST_F(MeshPipelineTest, EveryTriangleGetsAPatchMostFromThePhotos) {
  EXPECT_EQ(summary_->faces, 1280u);
  EXPECT_EQ(summary_->from_photos + summary_->from_neighbours + summary_->random, summary_->faces);
  EXPECT_GT(summary_->from_photos, summary_->faces * 6 / 10);
  EXPECT_LE(summary_->random, 1u);  // one connected mesh: at most the seed
  EXPECT_EQ(summary_->photos_used, 12u);
  for (const char* file :
       {"model.obj", "model.mtl", "model.glb", "manifest.json", "ptm_atlas_0.ptm",
        "ptm_atlas_0.exr", "base_colour_0.png", "albedo_0.png", "baked_0.png"}) {
    EXPECT_TRUE(fs::exists(tmp_->path() / "model" / file)) << file;
  }
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp_->path() / "model/manifest.json"));
  for (const auto& f : manifest["files"]) {
    EXPECT_TRUE(fs::exists(tmp_->path() / "model" / f.get<std::string>())) << f;
  }
  EXPECT_TRUE(manifest["timings_s"].contains("synthesis"));
  EXPECT_EQ(manifest["settings"]["sample_texel_size"].get<double>(), 0.004);
  EXPECT_EQ(manifest["settings"]["world_unit_mm"].get<double>(), 1000.0);
  // The photos' blur, one per photo (synth/photo_blur.h), within the candidates.
  EXPECT_TRUE(manifest["settings"]["photo_blur"].get<bool>());
  EXPECT_EQ(manifest["settings"]["search"], "coarse-to-fine");
  EXPECT_EQ(manifest["settings"]["search_candidates"].get<int>(), 16);
  const nlohmann::json& blur = manifest["summary"]["photo_blur"];
  ASSERT_EQ(blur.size(), manifest["summary"]["photo_gains"].size());
  for (const auto& sigma : blur) {
    EXPECT_GE(sigma.get<double>(), 0.0);
    EXPECT_LE(sigma.get<double>(), 2.0);
  }
}

// The coefficients baked into the atlas, relit in the frame a renderer derives
// from the texture coordinates, equal the synthesis relit in the triangle frame:
// catches any error in the frame rotations of unfolding, charts and bake.
TEST_F(MeshPipelineTest, AtlasFramesAgreeWithTriangleFrames) {
  const sfm::LoadedModel loaded = sfm::ReadModel(job_->model_dir);
  const mesh::TriangleMesh mesh = mesh::LoadMesh(job_->mesh_file).mesh;
  const sfm::VisibilityResult visibility = sfm::ComputeVisibility(mesh, loaded.reconstruction);
  const ptm::Ptm sample = ptm::ReadPtmExr(job_->sample_file);
  MeshSynthesisOptions so = job_->synthesis;
  const MeshSynthesis synthesis =
      SynthesizeMeshPtm(mesh, loaded.reconstruction, visibility, {}, sample, so);
  EXPECT_EQ(synthesis.num_from_photos, 0u);  // no photos: neighbours only
  for (const atlas::AtlasMode mode : {atlas::AtlasMode::kPerTriangle, atlas::AtlasMode::kCharts}) {
    atlas::AtlasOptions ao;
    ao.mode = mode;
    ao.atlas_size = 1024;
    const atlas::Atlases atlases = atlas::BuildAtlases(mesh, synthesis, ao);
    const auto& from = ptm::OrthonormalBasis::Hemisphere().FromOrthonormal();
    std::mt19937 rng(5);
    double worst = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
      const std::size_t f =
          std::uniform_int_distribution<std::size_t>(0, mesh.faces.size() - 1)(rng);
      const atlas::FacePlacement& fp = atlases.faces[f];
      const TrianglePatch& patch = synthesis.patches[f];
      std::vector<float> value(synthesis.sample_planes.size());
      Eigen::Matrix<double, 6, 1> q;
      // Texel at the centroid (nearest texel centre).
      const Eigen::Vector2d px = (fp.corners_px[0] + fp.corners_px[1] + fp.corners_px[2]) / 3.0;
      const ptm::Ptm& atlas = atlases.ptms[static_cast<std::size_t>(fp.atlas)];
      const std::size_t texel = static_cast<std::size_t>(std::floor(px.y())) * atlas.width +
                                static_cast<std::size_t>(std::floor(px.x()));
      const Eigen::Vector2d centre(std::floor(px.x()) + 0.5, std::floor(px.y()) + 0.5);
      // Recompute the frame value at that texel centre.
      synthesis.SampleBlended(static_cast<int>(f), fp.FrameFromAtlas(centre, synthesis.texel_size),
                              ao.blend_strip, value.data());
      for (int i = 0; i < 6; ++i) q[i] = value[static_cast<std::size_t>(i)];
      const Eigen::Matrix<double, 6, 1> a_at_texel = from * q;
      // Tangent frame from the texture coordinates (v up), as the renderer does.
      const Eigen::Vector3d e1 = mesh.Corner(f, 1) - mesh.Corner(f, 0);
      const Eigen::Vector3d e2 = mesh.Corner(f, 2) - mesh.Corner(f, 0);
      const auto& c = fp.corners_px;
      const double du1 = c[1].x() - c[0].x(), dv1 = -(c[1].y() - c[0].y());
      const double du2 = c[2].x() - c[0].x(), dv2 = -(c[2].y() - c[0].y());
      const Eigen::Vector3d dp_du = (e1 * dv2 - e2 * dv1) / (du1 * dv2 - du2 * dv1);
      const Eigen::Vector3d n = e1.cross(e2).normalized();
      const Eigen::Vector3d x_uv = (dp_du - n * n.dot(dp_du)).normalized();
      const Eigen::Vector3d y_uv = n.cross(x_uv);
      for (int l = 0; l < 4; ++l) {
        const Eigen::Vector3d light_world =
            (patch.frame.z_axis + 0.6 * std::cos(l * 1.7) * patch.frame.x_axis +
             0.6 * std::sin(l * 1.7) * patch.frame.y_axis)
                .normalized();
        const Eigen::Vector3d in_frame = patch.frame.DirectionInFrame(light_world);
        const Eigen::Vector3d in_uv(x_uv.dot(light_world), y_uv.dot(light_world),
                                    n.dot(light_world));
        std::array<float, 6> af;
        for (int i = 0; i < 6; ++i)
          af[static_cast<std::size_t>(i)] = static_cast<float>(a_at_texel[i]);
        const double expected = ptm::EvaluatePolynomial(af.data(), in_frame.x(), in_frame.y());
        const double got = ptm::EvaluatePolynomial(atlas.Coefficients(texel), in_uv.x(), in_uv.y());
        worst = std::max(worst, std::abs(expected - got));
      }
    }
    EXPECT_LT(worst, 2e-3) << (mode == atlas::AtlasMode::kCharts ? "charts" : "per triangle");
  }
}

TEST_F(MeshPipelineTest, BlendingMakesEdgesContinuous) {
  const sfm::LoadedModel loaded = sfm::ReadModel(job_->model_dir);
  const mesh::TriangleMesh mesh = mesh::LoadMesh(job_->mesh_file).mesh;
  const sfm::VisibilityResult visibility = sfm::ComputeVisibility(mesh, loaded.reconstruction);
  const ptm::Ptm sample = ptm::ReadPtmExr(job_->sample_file);
  const MeshSynthesis synthesis =
      SynthesizeMeshPtm(mesh, loaded.reconstruction, visibility, {}, sample, job_->synthesis);
  // Seam visibility: coefficient difference across each edge at its midpoint,
  // the two sides' own patches against the two sides' blended values.
  double raw = 0.0, blended = 0.0;
  int edges = 0;
  const std::size_t planes = synthesis.sample_planes.size();
  std::vector<float> a(planes), b(planes);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const Unfolding& u = synthesis.unfoldings[f][static_cast<std::size_t>(k)];
      if (u.face < 0) continue;
      const auto& c = synthesis.patches[f].corners_in_frame;
      const Eigen::Vector2d mid =
          0.5 * (c[static_cast<std::size_t>(k)] + c[static_cast<std::size_t>((k + 1) % 3)]);
      const Eigen::Vector2d mid_nb = u.rotation * mid + u.translation;
      auto diff = [&](bool blend) {
        if (blend) {
          synthesis.SampleBlended(static_cast<int>(f), mid, job_->synthesis.strip, a.data());
          synthesis.SampleBlended(u.face, mid_nb, job_->synthesis.strip, b.data());
        } else {
          synthesis.SamplePatch(static_cast<int>(f), mid, a.data());
          synthesis.SamplePatch(u.face, mid_nb, b.data());
        }
        Eigen::Matrix<double, 6, 1> qa, qb;
        for (int i = 0; i < 6; ++i)
          qa[i] = a[static_cast<std::size_t>(i)], qb[i] = b[static_cast<std::size_t>(i)];
        return (qa - u.coefficients_to_this * qb).squaredNorm();
      };
      raw += diff(false);
      blended += diff(true);
      ++edges;
    }
  }
  ASSERT_GT(edges, 3000);
  EXPECT_LT(blended, 0.05 * raw);
}

// The atlas pixels a face's corners span, with a pixel of margin on each side.
template <typename Corners>
cv::Rect FaceBox(const Corners& corners) {
  double x0 = corners[0].x(), x1 = x0, y0 = corners[0].y(), y1 = y0;
  for (const auto& c : corners) {
    x0 = std::min<double>(x0, c.x()), x1 = std::max<double>(x1, c.x());
    y0 = std::min<double>(y0, c.y()), y1 = std::max<double>(y1, c.y());
  }
  const int left = static_cast<int>(std::floor(x0)) - 1, top = static_cast<int>(std::floor(y0)) - 1;
  return {left, top, static_cast<int>(std::ceil(x1)) + 2 - left,
          static_cast<int>(std::ceil(y1)) + 2 - top};
}

TEST_F(MeshPipelineTest, AtlasFacesDoNotOverlapAndChartsPackTighter) {
  const model::TexturedModel model = model::ReadModelFolder(tmp_->path() / "model");
  std::vector<cv::Mat> owner;
  for (const ptm::Ptm& a : model.atlases)
    owner.push_back(cv::Mat(a.height, a.width, CV_32SC1, cv::Scalar(-1)));
  int overlaps = 0;
  for (std::size_t f = 0; f < model.mesh.faces.size(); ++f) {
    cv::Mat& o = owner[static_cast<std::size_t>(model.face_atlas[f])];
    // The face's texels strictly inside it, drawn in its bounding box (with a
    // texel of margin for the erosion).
    const cv::Rect box = cv::Rect(0, 0, o.cols, o.rows) & FaceBox(model.corner_px[f]);
    std::vector<cv::Point> poly;
    for (const auto& c : model.corner_px[f])
      poly.emplace_back(static_cast<int>(std::lround((c.x() - box.x) * 16)),
                        static_cast<int>(std::lround((c.y() - box.y) * 16)));
    cv::Mat mask = cv::Mat::zeros(box.size(), CV_8UC1);
    cv::fillConvexPoly(mask, poly, 255, cv::LINE_8, 4);
    cv::erode(mask, mask, cv::Mat());  // texels strictly inside
    for (int y = 0; y < box.height; ++y)
      for (int x = 0; x < box.width; ++x)
        if (mask.at<std::uint8_t>(y, x)) {
          int& owner_of = o.at<int>(box.y + y, box.x + x);
          if (owner_of >= 0) ++overlaps;
          owner_of = static_cast<int>(f);
        }
  }
  EXPECT_EQ(overlaps, 0);
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp_->path() / "model/manifest.json"));
  const double charts = manifest["summary"]["occupancy"].get<double>();
  pipeline::SynthJobOptions per_triangle = Job(tmp_->path() / "model_per_triangle");
  per_triangle.atlas.mode = atlas::AtlasMode::kPerTriangle;
  per_triangle.synthesis.correction_iterations = 0;  // the atlas does not depend on them
  per_triangle.synthesis.detail_transfer = false;
  per_triangle.write_report = false;
  const pipeline::SynthJobSummary s = pipeline::RunSynthJob(per_triangle);
  EXPECT_GT(s.occupancy, 0.3);
  EXPECT_LT(s.occupancy, 0.5);  // one box per triangle caps near 0.4 (DESIGN.md)
  EXPECT_GT(charts, s.occupancy);
  EXPECT_EQ(s.chart_flattening, "none");
  // The default (auto) says which flattening it chose.
  const std::string chosen = manifest["summary"]["chart_flattening"].get<std::string>();
  EXPECT_TRUE(chosen == "strips" || chosen == "rigid") << chosen;
  EXPECT_EQ(manifest["settings"]["chart_flattening"], "auto");
}

TEST_F(MeshPipelineTest, ModelFolderRoundTripsAndTheGlbIsWellFormed) {
  const model::TexturedModel model = model::ReadModelFolder(tmp_->path() / "model");
  const mesh::TriangleMesh mesh = mesh::LoadMesh(job_->mesh_file).mesh;
  ASSERT_EQ(model.mesh.faces.size(), mesh.faces.size());
  // The light response the job estimated from the photos comes back as written.
  EXPECT_FALSE(model.light_response.IsIdentity());
  EXPECT_EQ(model::LightResponseJson(model.light_response),
            model::LightResponseJson(summary_->model->light_response));
  ASSERT_EQ(model.mesh.vertices.size(), mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    ASSERT_LT((model.mesh.vertices[v] - mesh.vertices[v]).norm(), 1e-6);
  // GLB: header, chunk layout, JSON that parses, buffer views inside the buffer.
  const std::string glb = testing::ReadText(tmp_->path() / "model/model.glb");
  ASSERT_GT(glb.size(), 28u);
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, glb.data() + at, 4);
    return v;
  };
  EXPECT_EQ(u32(0), 0x46546C67u);
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), glb.size());
  const std::uint32_t json_length = u32(12);
  EXPECT_EQ(u32(16), 0x4E4F534Au);
  EXPECT_EQ(json_length % 4, 0u);
  const nlohmann::json gltf = nlohmann::json::parse(glb.substr(20, json_length));
  const std::uint32_t bin_length = u32(20 + json_length);
  EXPECT_EQ(u32(24 + json_length), 0x004E4942u);
  EXPECT_EQ(gltf["buffers"][0]["byteLength"].get<std::uint32_t>(), bin_length);
  for (const auto& view : gltf["bufferViews"]) {
    EXPECT_LE(view["byteOffset"].get<std::size_t>() + view["byteLength"].get<std::size_t>(),
              bin_length);
    EXPECT_EQ(view["byteOffset"].get<std::size_t>() % 4, 0u);
  }
  std::size_t triangles = 0;
  for (const auto& primitive : gltf["meshes"][0]["primitives"]) {
    triangles += gltf["accessors"][primitive["indices"].get<int>()]["count"].get<std::size_t>() / 3;
    const auto& material = gltf["materials"][primitive["material"].get<int>()];
    EXPECT_TRUE(material["extras"]["texlume_ptm"].contains("ptm"));
  }
  EXPECT_EQ(triangles, mesh.faces.size());
}

TEST_F(MeshPipelineTest, RendersHeldOutViewsAndComparesWithTheBaselines) {
  const pipeline::RenderJobSummary ptm = Render(render::RenderMode::kPtm, "render_ptm");
  const pipeline::RenderJobSummary flat = Render(render::RenderMode::kFlat, "render_flat");
  const pipeline::RenderJobSummary baked = Render(render::RenderMode::kBaked, "render_baked");
  ASSERT_EQ(ptm.rendered, 4u);
  ASSERT_EQ(ptm.metrics.size(), 4u);
  std::printf("held-out PSNR / SSIM: texlume %.2f / %.3f, flat %.2f / %.3f, baked %.2f / %.3f\n",
              ptm.mean_psnr, ptm.mean_ssim, flat.mean_psnr, flat.mean_ssim, baked.mean_psnr,
              baked.mean_ssim);
  // Relit structure: texlume's SSIM beats the flat baseline's, its PSNR the
  // baked photos' (which keep the photos' lights).
  EXPECT_GT(ptm.mean_ssim, flat.mean_ssim + 0.05);
  EXPECT_GT(ptm.mean_psnr, baked.mean_psnr);
  EXPECT_GT(ptm.mean_psnr, 15.0);
  // The rendered mask is the ground-truth mask.
  const fs::path held = tmp_->path() / "scene/object/held_out";
  for (const auto& entry : fs::directory_iterator(held / "masks")) {
    const cv::Mat truth = cv::imread(entry.path().string(), cv::IMREAD_GRAYSCALE) > 127;
    const cv::Mat ours =
        cv::imread((tmp_->path() / "render_ptm/masks" / entry.path().filename()).string(),
                   cv::IMREAD_GRAYSCALE) > 127;
    ASSERT_EQ(truth.size(), ours.size());
    const double iou =
        static_cast<double>(cv::countNonZero(truth & ours)) / cv::countNonZero(truth | ours);
    EXPECT_GT(iou, 0.95) << entry.path();
  }
  EXPECT_TRUE(fs::exists(tmp_->path() / "render_ptm/render.json"));
}

// Texels (inside faces or gutters) whose values differ between two models of
// one layout, and texels in all.
std::pair<std::size_t, std::size_t> ChangedTexels(const model::TexturedModel& a,
                                                  const model::TexturedModel& b) {
  std::size_t changed = 0, texels = 0;
  EXPECT_EQ(a.atlases.size(), b.atlases.size());
  for (std::size_t k = 0; k < std::min(a.atlases.size(), b.atlases.size()); ++k) {
    const ptm::Ptm &pa = a.atlases[k], &pb = b.atlases[k];
    EXPECT_EQ(pa.NumTexels(), pb.NumTexels());
    for (std::size_t t = 0; t < std::min(pa.NumTexels(), pb.NumTexels()); ++t) {
      const float* ca = pa.Coefficients(t);
      const float* cb = pb.Coefficients(t);
      bool differs = false, zero = true;
      for (int m = 0; m < 6; ++m) {
        differs = differs || std::abs(ca[m] - cb[m]) > 1e-6f;
        zero = zero && ca[m] == 0.0f && cb[m] == 0.0f;
      }
      texels += !zero;
      changed += differs;
    }
  }
  return {changed, texels};
}

// `--fill-unseen graphcut`: the faces no photo placed are quilted by the
// graph-cut engine from the faces the photos placed, which keep their texture
// (only their blend band next to a filled face changes). What the held-out
// views score with it is measured by bench/unseen_fill_bench.
TEST_F(MeshPipelineTest, GraphCutFillQuiltsOnlyTheFacesNoPhotoPlaced) {
  pipeline::SynthJobOptions job = Job(tmp_->path() / "model_fill");
  job.fill_unseen = pipeline::FillUnseen::kGraphcut;
  job.write_report = false;
  const pipeline::SynthJobSummary fill = pipeline::RunSynthJob(job);
  EXPECT_EQ(fill.from_photos, summary_->from_photos);
  EXPECT_EQ(fill.unseen_fill.faces, summary_->from_neighbours + summary_->random);
  ASSERT_GT(fill.unseen_fill.faces, 0u);
  EXPECT_GT(fill.unseen_fill.stats.patches, 1u);
  const auto [changed, texels] = ChangedTexels(*summary_->model, *fill.model);
  std::printf(
      "graph-cut fill: %zu faces, %zu samples quilted (%zu patches); %zu of %zu texels "
      "changed\n",
      fill.unseen_fill.faces, fill.unseen_fill.samples, fill.unseen_fill.stats.patches, changed,
      texels);
  EXPECT_GT(changed, fill.unseen_fill.samples / 2);
  EXPECT_LT(changed, 2 * fill.unseen_fill.samples);
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp_->path() / "model_fill/manifest.json"));
  EXPECT_EQ(manifest["settings"]["fill_unseen"], "graphcut");
  EXPECT_EQ(manifest["summary"]["unseen_fill"]["faces"].get<std::size_t>(), fill.unseen_fill.faces);
}

// The graph-cut engine following the photos (quilt/image_term.h): the photos
// are calibrated against the sample, most patches are placed among the
// photos' best placements, and the model folder and report record it.
TEST_F(MeshPipelineTest, GraphCutEngineFollowsThePhotos) {
  pipeline::QuiltJobOptions q;
  q.model_dir = job_->model_dir;
  q.images_dir = job_->images_dir;
  q.lights_file = job_->lights_file;
  q.mesh_file = job_->mesh_file;
  q.sample_file = job_->sample_file;
  q.sample_texel_size = 0.008;  // 4 texels of the sample's own: a fast run
  q.out_dir = tmp_->path() / "graphcut_photos";
  q.atlas.atlas_size = 512;
  const pipeline::QuiltJobSummary s = pipeline::RunQuiltJob(q);
  std::printf("graph-cut with photos: %zu patches, %zu placed by the photos, %.1f s\n",
              s.stats.patches, s.stats.photo_patches, s.seconds_total);
  EXPECT_EQ(s.photos_used, 12u);
  EXPECT_GT(s.stats.photo_patches, s.stats.patches / 2);
  EXPECT_LE(s.stats.photo_patches, s.stats.patches);
  const fs::path out = tmp_->path() / "graphcut_photos";
  const nlohmann::json manifest = nlohmann::json::parse(testing::ReadText(out / "manifest.json"));
  EXPECT_EQ(manifest["inputs"]["model"], job_->model_dir.string());
  EXPECT_EQ(manifest["settings"]["photos"]["top_k"].get<int>(), 12);
  EXPECT_EQ(manifest["summary"]["patches_placed_by_photos"].get<std::size_t>(),
            s.stats.photo_patches);
  EXPECT_EQ(manifest["summary"]["photos"]["photo_gains"].size(), 12u);
  EXPECT_TRUE(manifest["timings_s"].contains("photo_calibration"));
  // The model answers light as the photos showed, as the main job's does.
  const model::TexturedModel model = model::ReadModelFolder(out);
  EXPECT_FALSE(model.light_response.IsIdentity());
  EXPECT_EQ(model::LightResponseJson(model.light_response),
            manifest["summary"]["photos"]["light_response"]);
  // The report compares the model with the photos, and every picture it links exists.
  const std::string html = testing::ReadText(out / "report.html");
  EXPECT_NE(html.find("Photo views"), std::string::npos);
  for (const std::string& link : testing::ReportLinks(html))
    EXPECT_TRUE(fs::exists(out / link)) << link;
  // Photos need all three inputs.
  q.lights_file.clear();
  q.out_dir = tmp_->path() / "graphcut_bad";
  EXPECT_THROW(pipeline::RunQuiltJob(q), OptionError);
  EXPECT_FALSE(fs::exists(q.out_dir));
}

// Triangles far larger than the sample (the graph-cut engine's own case): the
// photos are calibrated on a midpoint subdivision of the mesh, whose faces fit
// the sample, instead of on no face at all (gains of 1 and the identity), and
// the photos' line field comes from the subdivision's frames.
TEST_F(MeshPipelineTest, GraphCutEngineCalibratesLargeTrianglesOnASubdivision) {
  const mesh::TriangleMesh sphere = mesh::LoadMesh(job_->mesh_file).mesh;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : sphere.vertices) centre += v;
  centre /= static_cast<double>(sphere.vertices.size());
  double radius = 0;
  for (const Eigen::Vector3d& v : sphere.vertices) radius += (v - centre).norm();
  radius /= static_cast<double>(sphere.vertices.size());
  mesh::TriangleMesh coarse = datasets::MakeIcosphere(0, radius);  // 20 faces
  for (Eigen::Vector3d& v : coarse.vertices) v += centre;
  const fs::path coarse_file = tmp_->path() / "icosahedron.ply";
  {
    std::ofstream ply(coarse_file);
    ply << std::setprecision(17) << "ply\nformat ascii 1.0\nelement vertex "
        << coarse.vertices.size()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face "
        << coarse.faces.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const Eigen::Vector3d& v : coarse.vertices)
      ply << v.x() << " " << v.y() << " " << v.z() << "\n";
    for (const auto& f : coarse.faces) ply << "3 " << f[0] << " " << f[1] << " " << f[2] << "\n";
  }
  const ptm::Ptm sample = ptm::ReadPtmExr(job_->sample_file);
  const int side = std::min(sample.width, sample.height);
  const double edge = (coarse.Corner(0, 1) - coarse.Corner(0, 0)).norm();
  pipeline::QuiltJobOptions q;
  q.model_dir = job_->model_dir;
  q.images_dir = job_->images_dir;
  q.lights_file = job_->lights_file;
  q.mesh_file = coarse_file;
  q.sample_file = job_->sample_file;
  q.sample_texel_size = edge / (1.5 * side);  // a face spans 1.5 samples; a quarter of it fits
  q.out_dir = tmp_->path() / "graphcut_icosahedron";
  q.atlas.atlas_size = 512;
  q.write_report = false;
  q.photo_engine.tangent_frame = synth::TangentFrame::kPhotos;  // the field from the calibration
  const pipeline::QuiltJobSummary s = pipeline::RunQuiltJob(q);
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(q.out_dir / "manifest.json"));
  const nlohmann::json& photos = manifest["summary"]["photos"];
  EXPECT_EQ(photos["mesh_subdivisions"].get<int>(), 1);
  EXPECT_EQ(photos["tangent_frame"], "photos");
  std::size_t calibrated = 0;
  for (const auto& gain : photos["photo_gains"]) calibrated += gain.get<double>() != 1.0;
  EXPECT_EQ(calibrated, s.photos_used);
  EXPECT_FALSE(model::ReadModelFolder(q.out_dir).light_response.IsIdentity());
  bool warned = false;
  for (const std::string& w : s.warnings) warned = warned || w.find("subdivided") != w.npos;
  EXPECT_TRUE(warned);
  EXPECT_GT(s.stats.photo_patches, 0u);
}

// What each pass (detail transfer, the photo-consistency prior's shrink) adds under
// held-out lights is a single-seed comparison: ABLATIONS=1 bench/fidelity_bench.sh
// measures it (docs/synth.md, "Ablations").

TEST_F(MeshPipelineTest, BadInputIsRefusedWithNothingWritten) {
  // Photos without files are skipped; none left is an error naming the folder.
  pipeline::SynthJobOptions j = Job(tmp_->path() / "bad1");
  j.images_dir = tmp_->path() / "no_such_images";
  EXPECT_THROW(pipeline::RunSynthJob(j), InputError);
  EXPECT_FALSE(fs::exists(tmp_->path() / "bad1"));
  // A mesh in another frame: most triangles seen by no photo.
  mesh::TriangleMesh moved = mesh::LoadMesh(job_->mesh_file).mesh;
  for (auto& v : moved.vertices) v += Eigen::Vector3d(50, 0, 0);
  mesh::SaveMesh(moved, tmp_->path() / "moved.ply");
  j = Job(tmp_->path() / "bad2");
  j.mesh_file = tmp_->path() / "moved.ply";
  try {
    pipeline::RunSynthJob(j);
    ADD_FAILURE() << "a mesh in another frame was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp_->path() / "bad2"));
  // A texel size that would need more texels than allowed: refused with the estimate.
  j = Job(tmp_->path() / "bad3");
  j.synthesis.sample_texel_size = 0.004;
  j.synthesis.max_texels = 1000;
  try {
    pipeline::RunSynthJob(j);
    ADD_FAILURE() << "an oversized job was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("texels"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp_->path() / "bad3"));
  // Patches and atlases beyond the memory limit (--memory-limit): refused up front with
  // the estimate (at half the texel size the patches take four times the texels).
  j = Job(tmp_->path() / "bad4");
  j.synthesis.sample_texel_size = 0.002;
  {
    struct MemoryLimit {  // the default again however the block ends
      explicit MemoryLimit(std::uint64_t bytes) { SetMemoryLimitBytes(bytes); }
      ~MemoryLimit() { SetMemoryLimitBytes(0); }
    } limit(64 << 20);
    try {
      pipeline::RunSynthJob(j);
      ADD_FAILURE() << "patches beyond the memory limit were accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the patches and atlases of"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("--memory-limit"), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(tmp_->path() / "bad4"));
  // An existing folder that is not a model is not replaced.
  fs::create_directories(tmp_->path() / "keep");
  testing::WriteText(tmp_->path() / "keep/notes.txt", "mine");
  EXPECT_THROW(pipeline::RunSynthJob(Job(tmp_->path() / "keep")), InputError);
  EXPECT_TRUE(fs::exists(tmp_->path() / "keep/notes.txt"));
  // A photo without a light is skipped with a warning naming it.
  sfm::ObjectLights lights = sfm::ReadObjectLightsFile(job_->lights_file);
  const std::string dropped = lights.begin()->first;
  lights.erase(lights.begin());
  sfm::WriteObjectLightsFile(lights, tmp_->path() / "fewer_lights.json");
  j = Job(tmp_->path() / "fewer");
  j.lights_file = tmp_->path() / "fewer_lights.json";
  j.synthesis.correction_iterations = 0;
  const pipeline::SynthJobSummary s = pipeline::RunSynthJob(j);
  EXPECT_EQ(s.photos_used, 11u);
  bool named = false;
  for (const std::string& w : s.warnings) named = named || w.find(dropped) != std::string::npos;
  EXPECT_TRUE(named);
}

}  // namespace
}  // namespace texlume::synth

namespace texlume::synth {
namespace {

// A texlume output, what of it must not depend on the run: JSON without its
// timings, HTML before its timings table, every other file as it is.
std::string WithoutTimings(const fs::path& file) {
  const std::string bytes = testing::ReadText(file);
  if (file.extension() == ".json") {
    nlohmann::json j = nlohmann::json::parse(bytes);
    std::function<void(nlohmann::json&)> strip = [&](nlohmann::json& v) {
      if (v.is_object()) {
        v.erase("timings_s");
        v.erase("resources");
        for (auto& [key, value] : v.items()) strip(value);
      } else if (v.is_array()) {
        for (auto& value : v) strip(value);
      }
    };
    strip(j);
    return j.dump();
  }
  if (file.extension() == ".html") {
    // The page names its own folder (the texlume view command), which differs by design.
    std::string page = bytes.substr(0, bytes.find("<h2>Timings</h2>"));
    const std::string folder = file.parent_path().string();
    for (std::size_t at; (at = page.find(folder)) != std::string::npos;)
      page.replace(at, folder.size(), "MODEL");
    return page;
  }
  return bytes;
}

// The same inputs and seed give the same outputs, byte for byte but for the
// timings, whether the job runs on one thread or two (issue 30).
TEST_F(MeshPipelineTest, OutputsAreTheSameOnOneThreadAndOnTwo) {
  // The fixture's model was made on two threads (SetUpTestSuite).
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  pipeline::RunSynthJob(Job(tmp_->path() / "model_1_thread"));
  omp_set_num_threads(threads);
  const fs::path one = tmp_->path() / "model_1_thread", two = tmp_->path() / "model";
  // Every file the model folder lists (manifest.json "files"), on both sides.
  const auto listed = [](const fs::path& dir) {
    return nlohmann::json::parse(testing::ReadText(dir / "manifest.json"))["files"];
  };
  const nlohmann::json files = listed(one);
  ASSERT_EQ(files, listed(two));
  ASSERT_GE(files.size(), 10u);
  for (const auto& name : files) {
    const fs::path relative = name.get<std::string>();
    EXPECT_TRUE(WithoutTimings(one / relative) == WithoutTimings(two / relative)) << relative;
  }
  // The memory estimate counts each searching thread's relit buffers (RelitScratch).
  const auto estimate = [](const fs::path& dir) {
    return nlohmann::json::parse(
               testing::ReadText(dir / "manifest.json"))["resources"]["patch_memory_estimate_bytes"]
        .get<double>();
  };
  // The fixture's model on two threads, this one on one.
  const ImageReader sample(job_->sample_file);
  EXPECT_NEAR(estimate(two) - estimate(one),
              RelitScratch::BytesAtMost(job_->synthesis.max_views,
                                        cv::Size(sample.width(), sample.height())),
              1.0);
}

// Photos on demand (issue 33): with a cache of the fewest photos a face needs (its
// max_views), the job visits the faces photo by photo, never holds more than the
// budget, decodes each photo a few times rather than once per face, and makes the
// same photometry and a model as good on held-out views.
TEST_F(MeshPipelineTest, PhotosOnDemandStayWithinTheirCacheAndKeepTheModel) {
  pipeline::SynthJobOptions j = Job(tmp_->path() / "model_small_cache");
  const pipeline::SynthInputs inputs = pipeline::LoadSynthInputs(j);
  const std::uint64_t photo_bytes = inputs.photo_cache->TotalBytes() / inputs.photos.size();
  j.photo_cache_bytes = static_cast<std::uint64_t>(j.synthesis.max_views) * photo_bytes;
  const pipeline::SynthJobSummary s = pipeline::RunSynthJob(j);
  const nlohmann::json record =
      nlohmann::json::parse(testing::ReadText(tmp_->path() / "model_small_cache/manifest.json"));
  const nlohmann::json& cache = record["summary"]["photo_cache"];
  ASSERT_FALSE(cache["holds_all"].get<bool>());
  EXPECT_EQ(cache["budget_bytes"].get<std::uint64_t>(), j.photo_cache_bytes);
  EXPECT_LE(cache["peak_bytes"].get<std::uint64_t>(), j.photo_cache_bytes);
  EXPECT_GT(record["resources"]["peak_resident_bytes"].get<std::uint64_t>(),
            cache["peak_bytes"].get<std::uint64_t>());
  const std::size_t photos = inputs.photos.size(), faces = s.faces;
  const auto decodes = cache["decodes"].get<std::size_t>();
  std::printf("photos on demand: %zu photos, %zu faces, %zu decodes\n", photos, faces, decodes);
  EXPECT_GT(photos, static_cast<std::size_t>(j.synthesis.max_views));
  EXPECT_LT(decodes, faces / 2);
  // The photometry observes the same views either way: the same gains.
  const nlohmann::json fixture =
      nlohmann::json::parse(testing::ReadText(tmp_->path() / "model/manifest.json"));
  const auto gains = record["summary"]["photo_gains"].get<std::vector<double>>();
  const auto fixture_gains = fixture["summary"]["photo_gains"].get<std::vector<double>>();
  ASSERT_EQ(gains.size(), fixture_gains.size());
  for (std::size_t p = 0; p < gains.size(); ++p) EXPECT_NEAR(gains[p], fixture_gains[p], 1e-9);
  EXPECT_TRUE(fixture["summary"]["photo_cache"]["holds_all"].get<bool>());
  EXPECT_EQ(fixture["summary"]["photo_cache"]["decodes"].get<std::size_t>(), photos);
  EXPECT_EQ(s.from_photos, summary_->from_photos);
  const pipeline::RenderJobSummary small =
      Render(render::RenderMode::kPtm, "render_small_cache", "model_small_cache");
  const pipeline::RenderJobSummary full = Render(render::RenderMode::kPtm, "render_full_cache");
  std::printf("held-out PSNR / SSIM: all photos held %.3f / %.4f, on demand %.3f / %.4f\n",
              full.mean_psnr, full.mean_ssim, small.mean_psnr, small.mean_ssim);
  EXPECT_NEAR(small.mean_psnr, full.mean_psnr, 0.3);
  EXPECT_NEAR(small.mean_ssim, full.mean_ssim, 0.02);
  // A cache of two faces' photos (not all of them): two threads search two faces at
  // once (each face's photos held while it is searched), without taking turns decoding.
  j.photo_cache_bytes = 2 * static_cast<std::uint64_t>(j.synthesis.max_views) * photo_bytes;
  ASSERT_LT(j.photo_cache_bytes, inputs.photo_cache->TotalBytes());
  j.out_dir = tmp_->path() / "model_two_faces_cache";
  const int threads = omp_get_max_threads();
  omp_set_num_threads(2);
  const pipeline::SynthJobSummary two = pipeline::RunSynthJob(j);
  omp_set_num_threads(threads);
  const auto two_decodes = nlohmann::json::parse(testing::ReadText(
      j.out_dir / "manifest.json"))["summary"]["photo_cache"]["decodes"]
                               .get<std::size_t>();
  std::printf("photos on demand, two faces' photos: %zu decodes\n", two_decodes);
  EXPECT_LT(two_decodes, faces / 2);
  EXPECT_EQ(two.from_photos, summary_->from_photos);
  // A cache too small for one face's photos is refused before anything is read.
  j.photo_cache_bytes = photo_bytes;
  j.out_dir = tmp_->path() / "model_too_small";
  EXPECT_THROW(pipeline::RunSynthJob(j), OptionError);
  EXPECT_FALSE(fs::exists(j.out_dir));
}

// The browser viewer's model: every face corner in the vertex streams, charts as
// the atlas built them, every channel within half a quantisation step, and the
// PTM evaluated from the web channels as from the atlas.
TEST_F(MeshPipelineTest, WebModelKeepsChartsAndThePtmWithinQuantisation) {
  const model::WebModel web = model::BuildWebModel(tmp_->path() / "model");
  const model::TexturedModel model = model::ReadModelFolder(tmp_->path() / "model");
  const nlohmann::json& scene = web.scene;
  ASSERT_EQ(scene["faces"].get<std::size_t>(), model.mesh.faces.size());
  const std::size_t vertices = model.mesh.faces.size() * 3;
  // position, normal, face_normal, tangent, uv, face, chart.
  EXPECT_EQ(web.files.at("geometry.bin").size(), vertices * (3 + 3 + 3 + 3 + 2 + 1 + 1) * 4);
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp_->path() / "model/manifest.json"));
  EXPECT_EQ(scene["charts"].get<int>(), manifest["summary"]["charts"].get<int>());
  const ptm::Ptm& atlas = model.atlases[0];
  const bool lrgb = atlas.format == ptm::PtmFormat::kLrgb;
  const nlohmann::json& textures = scene["atlases"][0]["textures"];
  ASSERT_EQ(textures.size(), lrgb ? 2u : 5u);  // 8 or 18 channels, four per texture
  // Channel i of the web model at texel (x, y), and the largest half step.
  std::vector<cv::Mat> bgra;
  double half_step = 0.0;
  for (const auto& t : textures) {
    bgra.push_back(cv::imdecode(web.files.at(t["file"].get<std::string>()), cv::IMREAD_UNCHANGED));
    ASSERT_EQ(bgra.back().type(), CV_8UC4);
    ASSERT_EQ(bgra.back().cols, atlas.width);
    ASSERT_EQ(bgra.back().rows, atlas.height);
    for (const auto& scale : t["scale"])
      half_step = std::max(half_step, scale.get<double>() / 510.0);
  }
  auto channel = [&](std::size_t i, int x, int y) {
    const nlohmann::json& t = textures[i / 4];
    const int bgra_of_rgba[4] = {2, 1, 0, 3};
    return bgra[i / 4].at<cv::Vec4b>(y, x)[bgra_of_rgba[i % 4]] / 255.0 *
               t["scale"][i % 4].get<double>() +
           t["bias"][i % 4].get<double>();
  };
  double worst_channel = 0.0, worst_rgb = 0.0;
  for (int y = 0; y < atlas.height; y += 7)
    for (int x = 0; x < atlas.width; x += 7) {
      const std::size_t t = static_cast<std::size_t>(y) * static_cast<std::size_t>(atlas.width) +
                            static_cast<std::size_t>(x);
      // What each channel holds (docs/viewer.md).
      std::array<double, 18> expected{};
      if (lrgb) {
        const double s =
            (atlas.colour[t * 3] + atlas.colour[t * 3 + 1] + atlas.colour[t * 3 + 2]) / 3.0;
        for (int i = 0; i < 6; ++i)
          expected[static_cast<std::size_t>(i)] = atlas.Coefficients(t)[i] * s;
        expected[6] = s > 1e-6 ? atlas.colour[t * 3] / s : 1.0;
        expected[7] = s > 1e-6 ? atlas.colour[t * 3 + 1] / s : 1.0;
      } else {
        for (int i = 0; i < 6; ++i)
          for (int c = 0; c < 3; ++c)
            expected[static_cast<std::size_t>(3 * i + c)] = atlas.Coefficients(t, c)[i];
      }
      for (std::size_t i = 0; i < (lrgb ? 8u : 18u); ++i)
        worst_channel = std::max(worst_channel, std::abs(channel(i, x, y) - expected[i]));
      // The PTM under a light at 40 degrees, from the web channels.
      const double lu = 0.45, lv = -0.41;
      const auto basis = ptm::PtmBasis(lu, lv);
      Eigen::Vector3d rgb = Eigen::Vector3d::Zero();
      if (lrgb) {
        double luminance = 0.0;
        for (std::size_t i = 0; i < 6; ++i) luminance += basis[i] * channel(i, x, y);
        const double r = channel(6, x, y), g = channel(7, x, y);
        rgb = luminance * Eigen::Vector3d(r, g, 3.0 - r - g);
      } else {
        for (int c = 0; c < 3; ++c)
          for (std::size_t i = 0; i < 6; ++i)
            rgb[c] += basis[i] * channel(3 * i + static_cast<std::size_t>(c), x, y);
      }
      worst_rgb = std::max(worst_rgb,
                           (rgb - atlas.Evaluate(t, lu, lv).cast<double>()).cwiseAbs().maxCoeff());
    }
  EXPECT_LE(worst_channel, half_step + 1e-6);
  EXPECT_LT(worst_rgb, 0.03);  // display values in [0, 1]: 8 bits per channel
  std::printf("web model: worst channel error %.4f (half step %.4f), worst RGB error %.4f\n",
              worst_channel, half_step, worst_rgb);
  EXPECT_TRUE(web.files.count("scene.json"));
}

// The model folder's report: every picture it shows exists and is listed in
// the manifest; the model agrees with the photos better than the flat baseline.
TEST_F(MeshPipelineTest, SynthReportShowsEveryPictureItLinks) {
  const fs::path model = tmp_->path() / "model";
  const std::string html = testing::ReadText(model / "report.html");
  for (const char* section : {"Material sample", "Constraint photos", "Photo views under the",
                              "Light sweep", "Atlases", "Metrics", "Timings"})
    EXPECT_NE(html.find(section), std::string::npos) << section;
  // The physical scale: 0.004 world units of 1 m per texel.
  EXPECT_NE(html.find("texel spans 0.004 world units (4 mm) on the object"), std::string::npos);
  EXPECT_NE(html.find(" mm) at the model's centre"), std::string::npos);
  const std::vector<std::string> links = testing::ReportLinks(html);
  EXPECT_GE(links.size(), 5u + 12u + 4u * 6u + 1u + 1u + 3u);
  for (const std::string& link : links) {
    EXPECT_EQ(link.find(".."), std::string::npos) << link;
    EXPECT_TRUE(fs::exists(model / link)) << link;
  }
  const nlohmann::json manifest = nlohmann::json::parse(testing::ReadText(model / "manifest.json"));
  const auto& files = manifest["files"];
  for (const char* f : {"report.html", "report/light_sweep.png", "report/atlas_0.png"})
    EXPECT_NE(std::find(files.begin(), files.end(), f), files.end()) << f;
  EXPECT_FALSE(fs::exists(tmp_->path() / ("model.partial-" + std::to_string(::getpid()))));
}

// The report drawn from held-out views with ground truth: its own metrics
// rank texlume above the flat baseline in SSIM, the light sweep lights the
// side the light is on, occupancy per atlas agrees with the layout's.
TEST_F(MeshPipelineTest, ReportOnHeldOutViewsMeasuresAndSweepsTheLight) {
  const model::TexturedModel model = model::ReadModelFolder(tmp_->path() / "model");
  const model::ModelBaselines baselines = model::ReadModelBaselines(tmp_->path() / "model", model);
  const fs::path held = tmp_->path() / "scene/object/held_out";
  const sfm::LoadedModel cameras = sfm::ReadModel(held / "sparse");
  const sfm::ObjectLights lights = sfm::ReadObjectLightsFile(held / "lights.json");
  report::ReportInputs in;
  in.title = "held-out <views> & \"truth\"";
  in.model = &model;
  pipeline::ReportScene scene;
  scene.model = &model;
  scene.flat_albedo = baselines.flat_albedo;
  scene.baked = baselines.baked;
  for (const auto& [id, image] : cameras.reconstruction.images) {
    render::PictureView v;
    v.name = image.name;
    v.camera = cameras.reconstruction.cameras.at(image.camera_id);
    v.cam_from_world = image.cam_from_world;
    v.lights = lights.at(image.name);
    v.reference_image = held / "images" / image.name;
    v.reference_mask = held / "masks" / image.name;
    scene.views.push_back(v);
  }
  in.views_heading = "Held-out views";
  in.occupancy = summary_->occupancy;
  scene.sweep_frames = 4;
  scene.picture_width = 160;
  pipeline::DrawReportPictures(scene, in);
  testing::TempDir out;
  const report::ReportSummary s = report::WriteReport(out.path(), in);
  const std::string html = testing::ReadText(out.path() / "report.html");
  EXPECT_NE(html.find("held-out &lt;views&gt; &amp; &quot;truth&quot;"), std::string::npos);
  for (const std::string& link : testing::ReportLinks(html))
    EXPECT_TRUE(fs::exists(out.path() / link)) << link;
  ASSERT_EQ(s.rows.size(), 4u * 3u);  // 4 views x texlume, flat, baked
  double ssim_texlume = 0, ssim_flat = 0;
  for (const report::ReportSummary::Row& r : s.rows) {
    EXPECT_GT(r.psnr, 12.0) << r.view << " " << r.model;
    if (r.model == "texlume") ssim_texlume += r.ssim;
    if (r.model == "flat") ssim_flat += r.ssim;
  }
  std::printf("report SSIM over 4 held-out views: texlume %.3f, flat %.3f\n", ssim_texlume / 4,
              ssim_flat / 4);
  EXPECT_GT(ssim_texlume, ssim_flat);
  // Sweep frames 0 and 2: the light on the right, then on the left.
  const cv::Mat strip = cv::imread((out.path() / "report/light_sweep.png").string());
  ASSERT_EQ(strip.cols % 4, 0);
  const int w = strip.cols / 4;
  auto halves = [&](int frame) {
    const cv::Mat f = strip.colRange(frame * w, (frame + 1) * w);
    return std::make_pair(cv::mean(f.colRange(0, w / 2))[1], cv::mean(f.colRange(w / 2, w))[1]);
  };
  const auto [left0, right0] = halves(0);
  const auto [left2, right2] = halves(2);
  EXPECT_GT(right0, 1.3 * left0);
  EXPECT_GT(left2, 1.3 * right2);
  // Per-atlas occupancy, weighted by atlas size, is the layout's.
  const std::vector<double> occupancy = report::AtlasOccupancies(model);
  double inside = 0, total = 0;
  for (std::size_t a = 0; a < occupancy.size(); ++a) {
    const double texels = static_cast<double>(model.atlases[a].width) * model.atlases[a].height;
    inside += occupancy[a] * texels;
    total += texels;
  }
  EXPECT_NEAR(inside / total, summary_->occupancy, 0.02);

  // A reference of the wrong size: an error naming it, the earlier report kept whole.
  pipeline::ReportScene bad = scene;
  bad.views[1].reference_image = held / "masks" / bad.views[0].name;
  bad.views[1].camera = bad.views[1].camera.Scaled(0.5);
  report::ReportInputs bad_report = in;
  EXPECT_THROW(pipeline::DrawReportPictures(bad, bad_report), InputError);
  // A photo that cannot be read while the report is written: the same.
  report::ReportInputs bad_photo = in;
  bad_photo.photos = {{"missing.png", out.path() / "missing.png", {}, {}}};
  EXPECT_THROW(report::WriteReport(out.path(), bad_photo), InputError);
  EXPECT_EQ(testing::ReadText(out.path() / "report.html"), html);
  EXPECT_TRUE(fs::exists(out.path() / "report/light_sweep.png"));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(out.path())) ++entries;
  EXPECT_EQ(entries, 2u);  // report.html and report/
}

}  // namespace
}  // namespace texlume::synth
