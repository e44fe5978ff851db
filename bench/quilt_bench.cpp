// Graph-cut quilting benchmarks (issue 32).
// Run: build/bench/quilt_bench [--sample S] [--ptm FILE] [--levels R] [--texel T]
//                               [--compare MODEL_DIR]
//        build/bench/quilt_bench --ptm FILE --models DIR,DIR,...  (their energies only)
//        build/bench/quilt_bench --part matching     (FFT against brute force only)
//        build/bench/quilt_bench --part parameters   (the T_c and r_w sweep only)
// Entire-patch matching (paper 004 §III-B) by FFT against brute force: a random
// LRGB PTM sample of S x S texels (default 256) is turned to several of the 72
// rotations; work images of 16, 32 and 64 texels a side, half synthesised (a
// random mask, seeded), are matched by both. Reports whether the two choose the
// same placement and the time ratio, measured in the same process.
//
// Then the quilting loop (paper 004 Fig. 4) over an icosphere of radius 0.5 (1280
// faces) in conformal charts at texel T (default 0.004 world units), with the
// PTM FILE (default: a smooth random 256^2 LRGB PTM) and work patches of R
// levels (default 32), against random placement (the same loop, patches placed at
// random and always accepted): patches, time, forced patches, the mean seam cost
// per cut link against a cut between unrelated texels, the share of the sample
// reused, and the nearest-patch energy of the baked atlas (quilt/patch_energy.h;
// also of the model folder MODEL_DIR's atlases, e.g. the per-triangle engine's
// with the same sample); then the time from about 12k to 1M samples. Last,
// meshes of several kinds quilted alike (a handle, creases, two components, a
// non-manifold line, an irregular lumpy 81920-face scan-like mesh): coverage,
// charts, seams, energy and time; and samples of several kinds (the scene
// generator's stone, brick and grooves captures) against random placement.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "datasets_synthetic/material.h"
#include "datasets_synthetic/scene.h"
#include "datasets_synthetic/shapes.h"
#include "model/model_io.h"
#include "ptm/fit.h"
#include "ptm/ptm_io.h"
#include "quilt/patch_energy.h"
#include "quilt/patch_matching.h"
#include "quilt/quilt_atlases.h"
#include "quilt/surface_quilting.h"
#include "synth/planar_synthesis.h"

using namespace texlume;

namespace {

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

ptm::Ptm RandomPtm(int side, unsigned seed) {
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, side, side);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.3f, 0.3f);
  for (float& c : p.coefficients) c = u(rng);
  std::fill(p.colour.begin(), p.colour.end(), 1.0f);
  return p;
}

// The share of the sample's texels that some surface sample shows.
double SampleReused(const quilt::QuiltResult& r, int width, int height) {
  std::vector<bool> used(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (const quilt::SampleLookup& l : r.lookups) {
    const int x = std::clamp(static_cast<int>(l.sample_px.x()), 0, width - 1);
    const int y = std::clamp(static_cast<int>(l.sample_px.y()), 0, height - 1);
    used[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(x)] = true;
  }
  return static_cast<double>(std::count(used.begin(), used.end(), true)) /
         static_cast<double>(used.size());
}

// The nearest-patch energy of a model's PTM atlases against the sample.
double AtlasEnergy(const std::vector<ptm::Ptm>& ptms, const std::vector<cv::Mat>& inside,
                   quilt::RotatedSample& rotated, int windows_per_atlas = 192) {
  double sum = 0;
  int windows = 0;
  for (std::size_t a = 0; a < ptms.size(); ++a) {
    std::vector<cv::Mat> planes = synth::ToOrthonormalPlanes(ptms[a]);
    planes.resize(rotated.Copy(0).planes.size());  // the coefficients: the sample's features
    quilt::PatchEnergyOptions o;
    o.windows = windows_per_atlas;
    const quilt::PatchEnergy e = quilt::NearestPatchEnergy(planes, inside[a], rotated, o);
    sum += e.per_texel * e.windows;
    windows += e.windows;
  }
  return windows ? sum / windows : 0.0;
}

// Texels inside the faces of a model read back (its texture coordinates).
std::vector<cv::Mat> InsideMasks(const model::TexturedModel& m) {
  std::vector<cv::Mat> inside;
  for (const ptm::Ptm& p : m.atlases) inside.push_back(cv::Mat::zeros(p.height, p.width, CV_8UC1));
  for (std::size_t f = 0; f < m.corner_px.size(); ++f) {
    std::array<Eigen::Vector2d, 3> c;
    for (int k = 0; k < 3; ++k)
      c[static_cast<std::size_t>(k)] = m.corner_px[f][static_cast<std::size_t>(k)].cast<double>();
    cv::Mat& mask = inside[static_cast<std::size_t>(m.face_atlas[f])];
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x)
        if (mesh::SignedDistanceToTriangle(c, Eigen::Vector2d(x + 0.5, y + 0.5)) <= 0)
          mask.at<std::uint8_t>(y, x) = 255;
  }
  return inside;
}

struct Quilted {
  quilt::QuiltResult result;
  atlas::Atlases atlases;
  std::size_t samples = 0, links_across_charts = 0, texels_inside = 0, synthesised = 0;
  int charts = 0;
};

Quilted QuiltMesh(const mesh::TriangleMesh& mesh, const synth::PtmSample& sample, double texel,
                  const quilt::QuiltOptions& q) {
  const synth::PatchGeometry g = synth::MakePatchGeometry(
      mesh, texel, 2, synth::TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
  atlas::AtlasOptions o;
  o.flattening = atlas::ChartFlattening::kConformal;
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, texel, o);
  const quilt::DenseSurface surface =
      quilt::DenseSurface::Build(mesh, layout, g.patches, g.unfoldings, texel);
  Quilted out;
  out.samples = surface.size();
  out.charts = layout.num_charts;
  out.links_across_charts = surface.chart_seam_links();
  out.result = quilt::QuiltSurface(surface, layout, sample, q);
  out.atlases = quilt::BakeQuiltedAtlases(surface, out.result, layout, g.patches, sample, 2);
  for (const cv::Mat& c : out.atlases.coverage) out.texels_inside += cv::countNonZero(c == 255);
  for (const quilt::SampleLookup& l : out.result.lookups) out.synthesised += l.synthesised;
  return out;
}

Quilted QuiltIcosphere(const synth::PtmSample& sample, int subdivisions, double texel,
                       const quilt::QuiltOptions& q) {
  return QuiltMesh(datasets::MakeIcosphere(subdivisions, 0.5), sample, texel, q);
}

// Meshes of several kinds, quilted alike: coverage, seams, energy and time.
void QuiltMeshes(const synth::PtmSample& sample, int levels, double texel) {
  quilt::RotatedSample rotated(sample);
  std::printf(
      "\nMeshes of several kinds (conformal charts, texel %g, r_w %d, the sample above):\n"
      "| mesh | faces | samples | texels inside faces | synthesised | charts | links across "
      "charts | patches | forced | seam cost / unrelated cut | nearest-patch energy | s |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      texel, levels);
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(3, 0.3);
  mesh::TriangleMesh apart = sphere;
  for (Eigen::Vector3d& v : apart.vertices) v.x() += 0.8;
  const std::pair<const char*, mesh::TriangleMesh> meshes[] = {
      {"icosphere", datasets::MakeIcosphere(3, 0.5)},
      {"torus (a handle)", datasets::MakeTorus(48, 20, 0.35, 0.15)},
      {"capped cylinder (creases)", datasets::MakeCylinder(32, 8, 0.3, 0.8)},
      {"two spheres (disconnected)", datasets::JoinMeshes(sphere, apart)},
      {"crossed planes (non-manifold)", datasets::MakeCrossedPlanes(16, 0.8)},
      {"scan-like (irregular, lumpy)", datasets::MakeScanLikeMesh(6, 0.5, 0.1, 1)}};
  for (const auto& [name, mesh] : meshes)
    for (const bool conformal : {true, false}) {
      quilt::QuiltOptions q;
      q.work_patch_levels = levels;
      q.conformal_work_images = conformal;
      const auto t0 = std::chrono::steady_clock::now();
      const Quilted run = QuiltMesh(mesh, sample, texel, q);
      const quilt::QuiltStats& st = run.result.stats;
      std::printf("| %s%s | %zu | %zu | %zu | %zu | %d | %zu | %zu | %zu | %.2f | %.4f | %.1f |\n",
                  name, conformal ? "" : ", rigid chart maps", mesh.faces.size(), run.samples,
                  run.texels_inside, run.synthesised, run.charts, run.links_across_charts,
                  st.patches, st.forced, quilt::SeamShare(st),
                  AtlasEnergy(run.atlases.ptms, run.atlases.coverage, rotated), Seconds(t0));
      std::fflush(stdout);
    }
}

// Per face of the icosphere, the world's z axis laid onto it (x near the poles):
// the field a directional sample follows.
std::vector<Eigen::Vector3d> UpField(const mesh::TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> field;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d n = (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                                  .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]])
                                  .normalized();
    const Eigen::Vector3d up =
        std::abs(n.z()) > 0.95 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
    field.push_back((up - up.dot(n) * n).normalized());
  }
  return field;
}

// The scene generator's capture of a material (256^2 under 40 lights, kept in
// the temporary folder between runs) fitted as an LRGB PTM.
ptm::Ptm CaptureOf(datasets::MaterialKind kind) {
  const std::filesystem::path work =
      std::filesystem::temp_directory_path() /
      ("texlume_quilt_bench_" + std::string(datasets::MaterialKindName(kind)));
  if (!std::filesystem::exists(work / "material/capture/lights.lp"))
    datasets::GenerateScene(datasets::MaterialOnlySceneOptions(kind, 256, 40), work);
  return datasets::FitSceneSample(work);
}

// Samples of several kinds (issue 32): the scene generator's stone (stochastic),
// brick (structured) and grooves (directional) captures, 256^2 under 40 lights,
// fitted into LRGB PTMs and quilted over the icosphere along the up field,
// against random placement.
void QuiltMaterials(int levels, double texel) {
  std::printf(
      "\nSamples of several kinds (icosphere of 1280 faces, texel %g, r_w %d, the sample's x "
      "axis along the world's z laid on each face):\n| sample | run | patches | forced | seam "
      "cost / unrelated cut | sample reused | nearest-patch energy | s |\n"
      "|---|---|---|---|---|---|---|---|\n",
      texel, levels);
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(3, 0.5);
  for (const datasets::MaterialKind kind :
       {datasets::MaterialKind::kStone, datasets::MaterialKind::kBrick,
        datasets::MaterialKind::kGrooves}) {
    const std::string name(datasets::MaterialKindName(kind));
    const ptm::Ptm fitted = CaptureOf(kind);
    const synth::PtmSample sample(fitted);
    quilt::RotatedSample rotated(sample);
    for (const bool random : {false, true}) {
      quilt::QuiltOptions q;
      q.work_patch_levels = levels;
      q.random_placement = random;
      q.field_in_world = UpField(sphere);
      const Quilted run = QuiltMesh(sphere, sample, texel, q);
      const quilt::QuiltStats& st = run.result.stats;
      std::printf("| %s | %s | %zu | %zu | %.2f | %.2f | %.4f | %.2f |\n", name.c_str(),
                  random ? "random placement" : "graph-cut quilting", st.patches, st.forced,
                  quilt::SeamShare(st), SampleReused(run.result, fitted.width, fitted.height),
                  AtlasEnergy(run.atlases.ptms, run.atlases.coverage, rotated), st.seconds);
      std::fflush(stdout);
    }
  }
}

// T_c and r_w by measurement (issue 32): the stone, brick and grooves captures
// quilted over the icosphere with r_w varied at the paper's T_c and T_c varied
// at the paper's r_w, two seeds each. The energy is measured over 384 windows
// per atlas (twice the tables above: 72 matches a window make it the cost).
void SweepParameters(double texel) {
  std::printf(
      "\nT_c and r_w (icosphere of 1280 faces, texel %g; two seeds each, the mean; "
      "nearest-patch energy over 384 windows per atlas):\n| sample | r_w | T_c | patches | "
      "forced | seam cost / unrelated cut | sample reused | nearest-patch energy | energy, "
      "seed 1 / seed 2 | quilting s |\n|---|---|---|---|---|---|---|---|---|---|\n",
      texel);
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(3, 0.5);
  const std::pair<int, double> settings[] = {{16, 0.6}, {32, 0.6}, {64, 0.6}, {32, 0.4}, {32, 0.8}};
  for (const datasets::MaterialKind kind :
       {datasets::MaterialKind::kStone, datasets::MaterialKind::kBrick,
        datasets::MaterialKind::kGrooves}) {
    const std::string name(datasets::MaterialKindName(kind));
    const ptm::Ptm fitted = CaptureOf(kind);
    const synth::PtmSample sample(fitted);
    quilt::RotatedSample rotated(sample);
    for (const auto& [levels, threshold] : settings) {
      double energy[2] = {0, 0}, seam = 0, reused = 0, seconds = 0;
      std::size_t patches = 0, forced = 0;
      for (const std::uint64_t seed : {1, 2}) {
        quilt::QuiltOptions q;
        q.work_patch_levels = levels;
        q.seam_threshold = threshold;
        q.seed = seed;
        if (kind != datasets::MaterialKind::kStone) q.field_in_world = UpField(mesh);
        const Quilted run = QuiltMesh(mesh, sample, texel, q);
        const quilt::QuiltStats& st = run.result.stats;
        energy[seed - 1] = AtlasEnergy(run.atlases.ptms, run.atlases.coverage, rotated, 384);
        seam += quilt::SeamShare(st) / 2;
        reused += SampleReused(run.result, fitted.width, fitted.height) / 2;
        seconds += st.seconds / 2;
        patches += st.patches;
        forced += st.forced;
      }
      std::printf("| %s | %d | %.1f | %.0f | %.0f | %.2f | %.2f | %.4f | %.4f / %.4f | %.2f |\n",
                  name.c_str(), levels, threshold, patches / 2.0, forced / 2.0, seam, reused,
                  (energy[0] + energy[1]) / 2, energy[0], energy[1], seconds);
      std::fflush(stdout);
    }
  }
}

void QuiltSphere(const ptm::Ptm& sample_ptm, int levels, double texel, const char* compare) {
  const synth::PtmSample sample(sample_ptm);
  quilt::RotatedSample rotated(sample);
  std::printf(
      "\nQuilting an icosphere of radius 0.5 (1280 faces, conformal charts), sample %d x %d, "
      "texel %g, r_w %d:\n",
      sample_ptm.width, sample_ptm.height, texel, levels);
  std::printf(
      "| | patches | ms per patch | s | forced | seam cost / unrelated cut | sample reused "
      "| nearest-patch energy |\n|---|---|---|---|---|---|---|---|\n");
  std::string accepted;
  for (const int run_kind : {0, 1, 3, 2}) {
    const bool random = run_kind == 2;
    quilt::QuiltOptions q;
    q.work_patch_levels = levels;
    q.random_placement = random;
    q.keep_old_seams = run_kind != 1;
    q.conformal_work_images = run_kind != 3;
    const Quilted run = QuiltIcosphere(sample, 3, texel, q);
    const quilt::QuiltStats& s = run.result.stats;
    std::printf("| %s | %zu | %.1f | %.2f | %zu | %.2f | %.2f | %.4f |\n",
                run_kind == 0   ? "graph-cut quilting"
                : run_kind == 1 ? "graph-cut, old seams not kept"
                : run_kind == 3 ? "graph-cut, rigid chart maps across charts"
                                : "random placement",
                s.patches, 1000 * s.seconds / std::max<std::size_t>(s.patches, 1), s.seconds,
                s.forced, quilt::SeamShare(s),
                SampleReused(run.result, sample_ptm.width, sample_ptm.height),
                AtlasEnergy(run.atlases.ptms, run.atlases.coverage, rotated));
    if (run_kind == 0) {
      accepted = "accepted at r_w:";
      for (const auto& [l, n] : s.accepted_at_levels) {
        char item[48];
        std::snprintf(item, sizeof item, " %d: %zu;", l, n);
        accepted += item;
      }
    }
  }
  std::printf("(graph-cut quilting %s)\n", accepted.c_str());
  if (compare) {
    const model::TexturedModel m = model::ReadModelFolder(compare);
    std::printf("| the model folder %s | | | | | | | %.4f |\n", compare,
                AtlasEnergy(m.atlases, InsideMasks(m), rotated));
  }
  std::printf("\nTime against the dense samples (graph-cut quilting, same sample and r_w):\n");
  std::printf(
      "| icosphere faces | samples | patches | s | us per sample |\n|---|---|---|---|---|\n");
  for (const auto& [subdivisions, t] :
       {std::pair{3, 4 * texel}, std::pair{3, 2 * texel}, std::pair{3, texel},
        std::pair{4, texel / 2}, std::pair{4, texel / 2.3}}) {
    quilt::QuiltOptions q;
    q.work_patch_levels = levels;
    const Quilted run = QuiltIcosphere(sample, subdivisions, t, q);
    std::printf("| %d | %zu | %zu | %.2f | %.1f |\n", 20 << (2 * subdivisions), run.samples,
                run.result.stats.patches, run.result.stats.seconds,
                1e6 * run.result.stats.seconds / static_cast<double>(run.samples));
  }
}

// The nearest-patch energy of model folders' atlases against the sample, over
// 4 times the windows of the tables above: texlume synth's engines on one mesh
// at one texel size.
void ModelEnergies(const ptm::Ptm& sample_ptm, const std::string& folders) {
  const synth::PtmSample sample(sample_ptm);
  quilt::RotatedSample rotated(sample);
  std::printf(
      "| model folder | atlases | nearest-patch energy (768 windows per atlas) |\n"
      "|---|---|---|\n");
  std::size_t begin = 0;
  while (begin < folders.size()) {
    const std::size_t end = std::min(folders.find(',', begin), folders.size());
    const std::string folder = folders.substr(begin, end - begin);
    const model::TexturedModel m = model::ReadModelFolder(folder);
    std::printf("| %s | %zu | %.4f |\n", folder.c_str(), m.atlases.size(),
                AtlasEnergy(m.atlases, InsideMasks(m), rotated, 768));
    std::fflush(stdout);
    begin = end + 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  int side = 256, levels = 32;
  double texel = 0.004;
  const char* ptm_file = nullptr;
  const char* compare = nullptr;
  const char* models = nullptr;
  bool only_matching = false, sweep = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--models")) models = argv[i + 1];
    if (!std::strcmp(argv[i], "--sample")) side = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--ptm")) ptm_file = argv[i + 1];
    if (!std::strcmp(argv[i], "--levels")) levels = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--texel")) texel = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--compare")) compare = argv[i + 1];
    if (!std::strcmp(argv[i], "--part")) {
      only_matching = !std::strcmp(argv[i + 1], "matching");
      sweep = !std::strcmp(argv[i + 1], "parameters");
      if (!only_matching && !sweep) {
        std::fprintf(stderr, "quilt_bench: --part is matching or parameters, not %s\n",
                     argv[i + 1]);
        return 2;
      }
    }
  }
  if (sweep) {
    SweepParameters(texel);
    return 0;
  }
  if (models && ptm_file) {
    ModelEnergies(ptm::ReadPtmFile(ptm_file), models);
    return 0;
  }
  const ptm::Ptm sample_ptm = RandomPtm(side, 1), work_ptm = RandomPtm(96, 2);
  const synth::PtmSample sample(sample_ptm), work_sample(work_ptm);
  quilt::RotatedSample rotated(sample), work_source(work_sample);
  const quilt::RotatedCopy& work_copy = work_source.Copy(0);
  std::printf("Entire-patch matching, LRGB PTM sample %d x %d (copies %d x %d, 6 features)\n", side,
              side, rotated.side(), rotated.side());
  std::printf("| work image | placements | same choice | FFT s | brute force s | ratio |\n");
  std::printf("|---|---|---|---|---|---|\n");
  cv::RNG rng(3);
  constexpr int kFftRepeats = 10;
  for (const int w : {16, 32, 64}) {
    double fft = 0, brute = 0;
    int same = 0, trials = 0;
    for (const int rotation : {0, 5, 18, 41}) {
      const quilt::RotatedCopy& copy = rotated.Copy(rotation);
      std::vector<cv::Mat> work;
      for (const cv::Mat& plane : work_copy.planes) work.push_back(plane(cv::Rect(0, 0, w, w)));
      cv::Mat mask(w, w, CV_32FC1);
      rng.fill(mask, cv::RNG::UNIFORM, 0, 1);
      cv::threshold(mask, mask, 0.5, 1.0, cv::THRESH_BINARY);  // half synthesised
      quilt::MatchEntirePatch(copy, work, mask);               // warm (allocations, caches)
      auto t0 = std::chrono::steady_clock::now();
      quilt::Placement a;
      for (int r = 0; r < kFftRepeats; ++r) a = quilt::MatchEntirePatch(copy, work, mask);
      fft += Seconds(t0) / kFftRepeats;
      t0 = std::chrono::steady_clock::now();
      const quilt::Placement b = quilt::MatchEntirePatchBruteForce(copy, work, mask);
      brute += Seconds(t0);
      same += a.x == b.x && a.y == b.y;
      ++trials;
    }
    const int positions = (rotated.side() - w + 1) * (rotated.side() - w + 1);
    std::printf("| %d x %d | %d | %d of %d | %.4f | %.4f | %.0fx |\n", w, w, positions, same,
                trials, fft / trials, brute / trials, brute / fft);
  }
  if (only_matching) return 0;
  const ptm::Ptm quilted =
      ptm_file ? ptm::ReadPtmFile(ptm_file) : datasets::SmoothRandomPtm(256, 7);
  QuiltSphere(quilted, levels, texel, compare);
  QuiltMeshes(synth::PtmSample(quilted), levels, texel);
  QuiltMaterials(levels, texel);
  return 0;
}
