// The main job's fill of the faces no photo sees (issue 32): the per-triangle
// engine's overlap-only placement (paper 003) against graph-cut quilting grown
// out from the faces the photos placed (`--fill-unseen graphcut`, paper 004 §III).
// Run: build/bench/unseen_fill_bench [--images N] [--shape sphere|cylinder|torus|plane]
//                                    [--seed S] [--work DIR]
// A scene is generated (N photos of 320 x 240, default 12, from a ring above the
// object, so that its underside is seen by none; a stone capture of 128^2 texels
// at 0.004, fitted into the sample PTM), and the main job runs twice on it, alike
// but for the fill. Over the atlas texels of the faces no photo placed it
// reports:
// - the nearest-patch energy against the sample (quilt/patch_energy.h: how far
//   each 8 x 8 window is from the sample's nearest one, at 72 rotations);
// - the mean feature jump between neighbouring texels of two different faces
//   over that between texels of one face (1: no triangle-shaped seams);
// and, for the whole model, the held-out views' PSNR and SSIM (which see few
// unseen faces), the fill's patches, seams and time.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "datasets_synthetic/scene.h"
#include "mesh/mesh.h"
#include "pipeline/render_job.h"
#include "pipeline/synth_job.h"
#include "ptm/fit.h"
#include "ptm/ptm_io.h"
#include "quilt/patch_energy.h"
#include "synth/planar_synthesis.h"

using namespace texlume;
namespace fs = std::filesystem;

namespace {

struct Args {
  int images = 12;
  datasets::SceneShape shape = datasets::SceneShape::kSphere;
  std::uint32_t seed = 1;
  fs::path work = "unseen_fill_bench";
};

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--images")
      a.images = std::stoi(value);
    else if (key == "--seed")
      a.seed = static_cast<std::uint32_t>(std::stoul(value));
    else if (key == "--work")
      a.work = value;
    else if (key == "--shape")
      a.shape = datasets::SceneShapeFromName(value).value();
  }
  return a;
}

datasets::SceneOptions Scene(const Args& a) {
  datasets::SceneOptions o =
      datasets::SmallObjectSceneOptions(a.shape, datasets::MaterialKind::kStone);
  o.seed = a.seed;
  o.num_images = a.images;
  o.num_held_out_views = 2;
  o.held_out_lights_per_view = 2;
  return o;
}

// Per atlas, the face each texel's centre lies in among `faces` (-1: none).
std::vector<cv::Mat> FaceIndex(const model::TexturedModel& m, const std::vector<bool>& faces) {
  std::vector<cv::Mat> index;
  for (const ptm::Ptm& p : m.atlases) index.push_back(cv::Mat(p.height, p.width, CV_32SC1, -1));
  for (std::size_t f = 0; f < m.corner_px.size(); ++f) {
    if (!faces[f]) continue;
    std::array<Eigen::Vector2d, 3> c;
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e30), hi = -lo;
    for (std::size_t k = 0; k < 3; ++k) {
      c[k] = m.corner_px[f][k].cast<double>();
      lo = lo.cwiseMin(c[k]), hi = hi.cwiseMax(c[k]);
    }
    cv::Mat& mask = index[static_cast<std::size_t>(m.face_atlas[f])];
    for (int y = std::max(0, static_cast<int>(lo.y()));
         y <= std::min(mask.rows - 1, static_cast<int>(hi.y())); ++y)
      for (int x = std::max(0, static_cast<int>(lo.x()));
           x <= std::min(mask.cols - 1, static_cast<int>(hi.x())); ++x)
        if (mesh::SignedDistanceToTriangle(c, Eigen::Vector2d(x + 0.5, y + 0.5)) <= 0)
          mask.at<int>(y, x) = static_cast<int>(f);
  }
  return index;
}

struct FillFigures {
  double energy = 0;      ///< nearest-patch energy per texel over the unseen faces
  double edge_ratio = 0;  ///< mean jump across faces / within a face
};

FillFigures Measure(const model::TexturedModel& m, const std::vector<cv::Mat>& index,
                    quilt::RotatedSample& rotated) {
  double energy = 0, across = 0, within = 0;
  int windows = 0;
  std::size_t n_across = 0, n_within = 0;
  for (std::size_t a = 0; a < m.atlases.size(); ++a) {
    std::vector<cv::Mat> planes = synth::ToOrthonormalPlanes(m.atlases[a]);
    planes.resize(rotated.Copy(0).planes.size());
    const cv::Mat inside = index[a] >= 0;
    quilt::PatchEnergyOptions o;
    o.windows = 384;
    const quilt::PatchEnergy e = quilt::NearestPatchEnergy(planes, inside, rotated, o);
    energy += e.per_texel * e.windows;
    windows += e.windows;
    for (int y = 0; y + 1 < index[a].rows; ++y)
      for (int x = 0; x + 1 < index[a].cols; ++x) {
        const int f = index[a].at<int>(y, x);
        if (f < 0) continue;
        for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
          const int g = index[a].at<int>(y + dy, x + dx);
          if (g < 0) continue;
          double d2 = 0;
          for (const cv::Mat& p : planes)
            d2 += std::pow(p.at<float>(y, x) - p.at<float>(y + dy, x + dx), 2);
          (f == g ? within : across) += std::sqrt(d2);
          ++(f == g ? n_within : n_across);
        }
      }
  }
  FillFigures r;
  r.energy = windows ? energy / windows : 0.0;
  r.edge_ratio = n_across && n_within ? (across / n_across) / (within / n_within) : 0.0;
  return r;
}

// The graph-cut fills compared: the defaults, then variations of r_w, T_c and
// the old seams.
struct FillRun {
  std::string name;
  quilt::QuiltOptions quilt;
};
std::vector<FillRun> FillRuns() {
  std::vector<FillRun> runs(5);
  runs[0].name = "graphcut (r_w 32, T_c 0.6)";
  runs[1].name = "graphcut, old seams not kept";
  runs[1].quilt.keep_old_seams = false;
  runs[2].name = "graphcut, r_w 16";
  runs[2].quilt.work_patch_levels = 16;
  runs[3].name = "graphcut, T_c 0.3";
  runs[3].quilt.seam_threshold = 0.3;
  runs[4].name = "graphcut, r_w 64";
  runs[4].quilt.work_patch_levels = 64;
  return runs;
}

pipeline::RenderJobSummary RenderHeldOut(const fs::path& scene, const fs::path& model,
                                         const fs::path& out) {
  pipeline::RenderJobOptions r;
  r.model_folder = model;
  r.cameras_dir = scene / "object/held_out/sparse";
  r.lights_file = scene / "object/held_out/lights.json";
  r.out_dir = out;
  r.truth_images_dir = scene / "object/held_out/images";
  r.truth_masks_dir = scene / "object/held_out/masks";
  return pipeline::RunRenderJob(r);
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = Parse(argc, argv);
  const fs::path scene = args.work / "scene";
  datasets::GenerateScene(Scene(args), scene);
  const ptm::Ptm sample = datasets::FitSceneSample(scene);
  ptm::WritePtmExr(sample, args.work / "sample.exr");
  pipeline::SynthJobOptions job;
  job.model_dir = scene / "object/sparse";
  job.images_dir = scene / "object/images";
  job.lights_file = scene / "object/lights.json";
  job.mesh_file = scene / "object/mesh.ply";
  job.sample_file = args.work / "sample.exr";
  job.synthesis.sample_texel_size = 0.004;
  job.write_report = false;
  job.out_dir = args.work / "overlap";
  const pipeline::SynthJobSummary overlap = pipeline::RunSynthJob(job);
  const synth::PtmSample ptm_sample(sample);
  quilt::RotatedSample rotated(ptm_sample);
  std::vector<cv::Mat> index;  // the unseen faces' texels, from the first graph-cut run
  std::printf(
      "| fill | faces filled | samples quilted | patches | forced | seam / unrelated cut | "
      "nearest-patch energy (unseen faces) | jump across faces / within | held-out PSNR (dB) | "
      "SSIM | fill s | synthesis s |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const FillRun& run : FillRuns()) {
    job.fill_unseen = pipeline::FillUnseen::kGraphcut;
    job.fill_quilt = run.quilt;
    job.out_dir = args.work / "graphcut";
    const pipeline::SynthJobSummary graphcut = pipeline::RunSynthJob(job);
    const quilt::UnseenFillSummary& fill = graphcut.unseen_fill;
    if (fill.faces == 0) {
      std::printf("every face was placed from photos: nothing to fill\n");
      return 0;
    }
    if (index.empty()) {
      index = FaceIndex(*graphcut.model, fill.filled);
      const FillFigures o = Measure(*overlap.model, index, rotated);
      const auto ro = RenderHeldOut(scene, args.work / "overlap", args.work / "render");
      std::printf("| overlap | %zu | | | | | %.4f | %.2f | %.3f | %.4f | | %.1f |\n", fill.faces,
                  o.energy, o.edge_ratio, ro.mean_psnr, ro.mean_ssim, overlap.seconds_synthesis);
    }
    const FillFigures g = Measure(*graphcut.model, index, rotated);
    const auto rg = RenderHeldOut(scene, job.out_dir, args.work / "render");
    const quilt::QuiltStats& q = fill.stats;
    std::printf("| %s | %zu | %zu | %zu | %zu | %.2f | %.4f | %.2f | %.3f | %.4f | %.1f | %.1f |\n",
                run.name.c_str(), fill.faces, fill.samples, q.patches, q.forced,
                quilt::SeamShare(q), g.energy, g.edge_ratio, rg.mean_psnr, rg.mean_ssim,
                fill.seconds, graphcut.seconds_synthesis);
    std::fflush(stdout);
  }
  return 0;
}
