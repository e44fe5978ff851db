// Graph-cut quilting benchmarks (issue 32).
// Run: build/bench/quilt_bench [--sample S] [--ptm FILE] [--levels R] [--texel T]
// Entire-patch matching (paper 004 §III-B) by FFT against brute force: a random
// LRGB PTM sample of S x S texels (default 256) is turned to several of the 72
// rotations; work images of 16, 32 and 64 texels a side, half synthesised (a
// random mask, seeded), are matched by both. Reports whether the two choose the
// same placement and the time ratio, measured in the same process.
//
// Then the quilting loop (paper 004 Fig. 4) over an icosphere of radius 0.5 (1280
// faces) in conformal charts at texel T (default 0.004 world units), with the
// PTM FILE (default: a smooth random 256^2 LRGB PTM) and work patches of R
// levels (default 32): samples, patches accepted at each r_w, forced patches,
// the mean seam cost per cut link against a cut between unrelated texels, time.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "datasets_synthetic/shapes.h"
#include "ptm/ptm_io.h"
#include "quilt/patch_matching.h"
#include "quilt/surface_quilting.h"

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

ptm::Ptm SmoothPtm(int side, unsigned seed) {
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, side, side);
  cv::RNG rng(seed);
  for (int m = 0; m < 6; ++m) {
    cv::Mat coarse(side / 8, side / 8, CV_32FC1), plane;
    rng.fill(coarse, cv::RNG::UNIFORM, -0.3, 0.3);
    cv::resize(coarse, plane, cv::Size(side, side), 0, 0, cv::INTER_CUBIC);
    for (int t = 0; t < side * side; ++t)
      p.Coefficients(static_cast<std::size_t>(t))[m] =
          plane.at<float>(t / side, t % side) + (m == 5 ? 0.5f : 0.0f);
  }
  std::fill(p.colour.begin(), p.colour.end(), 1.0f);
  return p;
}

void QuiltSphere(const ptm::Ptm& sample_ptm, int levels, double texel) {
  const synth::PtmSample sample(sample_ptm);
  const mesh::TriangleMesh mesh = datasets::MakeIcosphere(3, 0.5);
  const synth::PatchGeometry g = synth::MakePatchGeometry(
      mesh, texel, 4, synth::TangentFrame::kFirstEdge, Eigen::Vector3d::UnitZ());
  atlas::AtlasOptions o;
  o.flattening = atlas::ChartFlattening::kConformal;
  const atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, g.patches, g.unfoldings, texel, o);
  auto t0 = std::chrono::steady_clock::now();
  const quilt::DenseSurface surface =
      quilt::DenseSurface::Build(layout, g.patches, g.unfoldings, texel);
  const double build_s = Seconds(t0);
  quilt::QuiltOptions q;
  q.work_patch_levels = levels;
  const quilt::QuiltResult r = quilt::QuiltSurface(surface, layout, sample, q);
  std::printf("\nQuilting an icosphere (1280 faces, %d charts), sample %d x %d, texel %g:\n",
              layout.num_charts, sample_ptm.width, sample_ptm.height, texel);
  std::printf("- %zu samples, %zu links (%zu across charts); dense surface %.2f s\n",
              surface.size(), surface.links(), surface.chart_seam_links(), build_s);
  std::printf("- %zu patches, %.1f ms each, %.2f s in all; forced %zu\n", r.stats.patches,
              1000 * r.stats.seconds / std::max<std::size_t>(r.stats.patches, 1), r.stats.seconds,
              r.stats.forced);
  std::printf("- accepted at r_w:");
  for (const auto& [l, n] : r.stats.accepted_at_levels) std::printf(" %d: %zu;", l, n);
  std::printf(
      "\n- seam cost per cut link %.4f, a cut between unrelated texels %.4f (ratio %.2f)\n",
      r.stats.seam_cost / std::max<std::size_t>(r.stats.cut_links, 1), r.stats.random_pair_cost,
      r.stats.seam_cost / std::max<std::size_t>(r.stats.cut_links, 1) / r.stats.random_pair_cost);
}

}  // namespace

int main(int argc, char** argv) {
  int side = 256, levels = 32;
  double texel = 0.004;
  const char* ptm_file = nullptr;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--sample")) side = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--ptm")) ptm_file = argv[i + 1];
    if (!std::strcmp(argv[i], "--levels")) levels = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--texel")) texel = std::atof(argv[i + 1]);
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
  for (const int w : {16, 32, 64}) {
    double fft = 0, brute = 0;
    int same = 0, trials = 0;
    for (const int rotation : {0, 5, 18, 41}) {
      const quilt::RotatedCopy& copy = rotated.Copy(rotation);
      std::vector<cv::Mat> work;
      for (const cv::Mat& plane : work_copy.planes) work.push_back(plane(cv::Rect(0, 0, w, w)));
      cv::Mat mask(w, w, CV_32FC1);
      rng.fill(mask, cv::RNG::UNIFORM, 0, 2);
      mask.convertTo(mask, CV_32S);
      mask.convertTo(mask, CV_32F);
      auto t0 = std::chrono::steady_clock::now();
      const quilt::Placement a = quilt::MatchEntirePatch(copy, work, mask);
      fft += Seconds(t0);
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
  QuiltSphere(ptm_file ? ptm::ReadPtmFile(ptm_file) : SmoothPtm(256, 7), levels, texel);
  return 0;
}
