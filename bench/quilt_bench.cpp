// Graph-cut quilting benchmarks (issue 32). Run: build/bench/quilt_bench [--sample S]
// Entire-patch matching (paper 004 §III-B) by FFT against brute force: a random
// LRGB PTM sample of S x S texels (default 256) is turned to several of the 72
// rotations; work images of 16, 32 and 64 texels a side, half synthesised (a
// random mask, seeded), are matched by both. Reports whether the two choose the
// same placement and the time ratio, measured in the same process.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <opencv2/core.hpp>
#include <random>

#include "quilt/patch_matching.h"

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

}  // namespace

int main(int argc, char** argv) {
  int side = 256;
  for (int i = 1; i + 1 < argc; i += 2)
    if (!std::strcmp(argv[i], "--sample")) side = std::atoi(argv[i + 1]);
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
  return 0;
}
