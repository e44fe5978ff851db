// PTM fitting benchmarks (issues 4 and 33). Run: build/bench/ptm_fit_bench [--images N]
//   [--size S | --width W --height H] [--format png|jpg] [--part all|throughput|horizon]
// 1. Throughput: N synthetic RTI images of S x S (or W x H) pixels (default 50 of
//    2048 x 2048, 4.2 MP; issue 33 measures 50 JPEGs of 6000 x 4000, 24 MP) are
//    written once, then in one run: decoding every band of every image alone on one
//    thread (the baseline), and decode + least-squares fit + .ptm write, LRGB and RGB.
//    Reports the ratios and the process's peak memory (run with two values of N to
//    see that memory does not grow with the number of images beyond one band).
// 2. Leave-out quality: on a synthetic stone capture (texlume scene), PSNR of the
//    PTM relit at the 10 held-out lights, least squares vs robust.
// 3. PTM against HSH (issue 31): on the stone, brick and grooves captures (texlume
//    scene, 256 x 256, 40 lights, realistic sensor), every fourth light held out; PSNR at
//    the held-out lights of LRGB and RGB PTMs and order-2 and order-3 HSH fitted to the
//    other three quarters (then the same without sensor noise); and the distance between the
//    luma-gradient histograms of the relit images and the held-out photos (render/fidelity.h),
//    beside that of another instance of the material (material seed 1001) photographed under the
//    same lights: how much of the relief's sharpness each basis keeps (issue 29's gradient aim).
// 4. Self-shadowing (issue 29; --part horizon): on the same captures and split, an RGB PTM
//    relit as it is, and times the visibility of a horizon map (ptm/horizon.h), the
//    PTM then refitted to the lit samples only: the horizon from the true relief
//    (material/ground_truth/height.exr, the bound of what self-shadowing costs) and from
//    the PTM's own normals integrated. PSNR and gradient distance at every held-out light
//    and at those below 35 degrees of elevation, where the relief's shadows are longest.
#include <OpenImageIO/imageio.h>
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "core/srgb.h"
#include "datasets_synthetic/renderer.h"
#include "datasets_synthetic/scene.h"
#include "ptm/exr_io.h"
#include "ptm/fit.h"
#include "ptm/horizon.h"
#include "ptm/hsh.h"
#include "ptm/image_bands.h"
#include "ptm/least_squares_bands.h"
#include "ptm/ptm_io.h"
#include "ptm/shadowed_fit.h"
#include "render/fidelity.h"
#include "sfm/lights.h"

namespace fs = std::filesystem;
using namespace texlume;

namespace {

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double PeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// Writes (once) n images of width x height pixels of a smooth random PTM relit at
// dome lights, as PNG or JPEG (quality 90, as cameras write them).
std::vector<fs::path> ThroughputImages(int n, cv::Size size, const std::string& format,
                                       const fs::path& dir, std::vector<Eigen::Vector3d>* lights) {
  *lights = datasets::DomeLights(n, 15, 80, 0.0);
  fs::create_directories(dir);
  std::vector<fs::path> files;
  cv::Mat a[6];
  cv::RNG rng(1);
  for (int i = 0; i < 6; ++i) {
    cv::Mat small(16, 16, CV_32FC1);
    rng.fill(small, cv::RNG::UNIFORM, -0.25, 0.25);
    cv::resize(small, a[i], size, 0, 0, cv::INTER_CUBIC);
  }
  cv::Mat grain(size, CV_32FC1);  // fine texture, so that JPEG has detail to code
  rng.fill(grain, cv::RNG::NORMAL, 0.0, 0.03);
  for (int k = 0; k < n; ++k) {
    files.push_back(dir / ("img_" + std::to_string(k) + "." + format));
    if (fs::exists(files.back())) continue;
    const auto b = ptm::PtmBasis((*lights)[static_cast<std::size_t>(k)].x(),
                                 (*lights)[static_cast<std::size_t>(k)].y());
    cv::Mat l = grain + 0.55;
    for (int i = 0; i < 6; ++i) l += b[static_cast<std::size_t>(i)] * a[i];
    cv::Mat image;
    cv::merge(std::vector<cv::Mat>{0.8 * l, 0.9 * l, l}, image);  // BGR
    image.convertTo(image, CV_8UC3, 255.0);
    const std::string tmp = files.back().string() + ".tmp." + format;
    cv::imwrite(tmp, image, {cv::IMWRITE_JPEG_QUALITY, 90});
    fs::rename(tmp, files.back());
  }
  return files;
}

// Every band of every image decoded alone, in the file's own 8-bit values, on one
// thread: what a reader must do at the least.
double DecodeOnly(const std::vector<fs::path>& files, int band_rows) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<OIIO::ImageInput>> inputs;
  for (const auto& f : files) inputs.push_back(OIIO::ImageInput::open(f.string()));
  const int width = inputs[0]->spec().width, height = inputs[0]->spec().height;
  std::vector<std::uint8_t> band(static_cast<std::size_t>(band_rows) * width * 3);
  double checksum = 0;
  for (int y0 = 0; y0 < height; y0 += band_rows) {
    const int rows = std::min(band_rows, height - y0);
    for (auto& in : inputs) {
      in->read_scanlines(0, 0, y0, y0 + rows, 0, 0, 3, OIIO::TypeDesc::UINT8, band.data());
      checksum += band[0];
    }
  }
  if (checksum < 0) std::printf("impossible\n");
  return Seconds(t0);
}

// The same through ptm::ImageBands: the next band decoded by every hardware thread
// while nothing is done with the current one (how fast the fit's reader can go).
double DecodeBands(const std::vector<fs::path>& files, int band_rows) {
  const auto t0 = std::chrono::steady_clock::now();
  ptm::ImageBands bands(files);
  std::atomic<long> checksum{0};  // the calls run on several threads at once
  bands.ForEach<std::uint8_t>(
      band_rows,
      [&](const std::vector<const std::uint8_t*>& pixels, int, int) { checksum += pixels[0][0]; },
      {}, "decode");
  if (checksum < 0) std::printf("impossible\n");
  return Seconds(t0);
}

// The least-squares kernel alone on one thread: n random 8-bit planar bands of
// width x 32 texels in memory, fitted 20 times; nanoseconds per texel and image.
double KernelNanoseconds(int n, int width, ptm::PtmFormat format) {
  const int rows = 32, repeats = 20;
  const auto lights = datasets::DomeLights(n, 15, 80, 0.0);
  std::mt19937 rng(3);
  std::vector<std::vector<std::uint8_t>> bands(static_cast<std::size_t>(n));
  std::vector<const std::uint8_t*> pixels;
  for (auto& band : bands) {
    band.resize(static_cast<std::size_t>(width) * rows * 3);
    for (auto& v : band) v = static_cast<std::uint8_t>(rng() & 255);
    pixels.push_back(band.data());
  }
  const ptm::LeastSquaresBands fitter(lights);
  ptm::Ptm out;
  out.Resize(format, width, rows);
  std::vector<float> residual(out.NumTexels());
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  double best = INFINITY;
  for (int trial = 0; trial < 3; ++trial) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < repeats; ++r) fitter.Fit(pixels, 255.0, rows, width, 0, out, residual);
    best = std::min(best, Seconds(t0));
  }
  omp_set_num_threads(threads);
  return best * 1e9 / (static_cast<double>(n) * width * rows * repeats);
}

double Psnr(const std::vector<float>& a, const cv::Mat& b_linear_rgb) {
  double sum = 0;
  for (int y = 0; y < b_linear_rgb.rows; ++y)
    for (int x = 0; x < b_linear_rgb.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = a[(static_cast<std::size_t>(y) * b_linear_rgb.cols + x) * 3 +
                           static_cast<std::size_t>(c)] -
                         b_linear_rgb.at<cv::Vec3f>(y, x)[c];
        sum += d * d;
      }
  return 10 * std::log10(1.0 / (sum / (b_linear_rgb.total() * 3.0)));
}

cv::Mat ReadRgb(const fs::path& file) {
  const cv::Mat image = cv::imread(file.string());
  cv::Mat rgb;
  image.convertTo(rgb, CV_32FC3, 1 / 255.0);
  cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

cv::Mat AsImage(const std::vector<float>& rgb, cv::Size size) {
  return cv::Mat(size, CV_32FC3, const_cast<float*>(rgb.data())).clone();
}

// Mean over the held-out lights of the gradient-histogram distance (luma per pixel).
double MeanGradientDistance(const std::vector<cv::Mat>& images, const std::vector<cv::Mat>& truth) {
  const cv::Mat mask(truth[0].size(), CV_8UC1, cv::Scalar(255));
  double sum = 0;
  for (std::size_t k = 0; k < truth.size(); ++k)
    sum += render::CompareAppearance(render::MeasureAppearance(images[k], mask),
                                     render::MeasureAppearance(truth[k], mask))
               .gradient_histogram_distance;
  return sum / static_cast<double>(truth.size());
}

struct HeldOutSplit {
  ptm::RtiCapture train, held;
};

// Every fourth light held out.
HeldOutSplit SplitCapture(const fs::path& scene_dir) {
  const ptm::RtiCapture all =
      ptm::ReadRtiCapture(scene_dir / "material/capture/lights.lp", scene_dir / "material/capture");
  HeldOutSplit split;
  for (std::size_t k = 0; k < all.files.size(); ++k) {
    ptm::RtiCapture& to = k % 4 == 3 ? split.held : split.train;
    to.files.push_back(all.files[k]);
    to.lights.push_back(all.lights[k]);
  }
  return split;
}

// Section 3: each basis fitted to three lights in four, measured at the fourth.
void PtmAgainstHsh(const fs::path& work, bool realistic) {
  for (const datasets::MaterialKind kind :
       {datasets::MaterialKind::kStone, datasets::MaterialKind::kBrick,
        datasets::MaterialKind::kGrooves}) {
    datasets::SceneOptions scene = datasets::MaterialOnlySceneOptions(kind, 256, 40);
    if (realistic) datasets::UseRealisticCapture(scene);
    const std::string name =
        std::string(datasets::MaterialKindName(kind)) + (realistic ? "" : "_clean");
    const fs::path dir = work / ("hsh_" + name), other_dir = work / ("hsh_" + name + "_other");
    if (!fs::exists(dir / "material/capture/lights.lp")) datasets::GenerateScene(scene, dir);
    scene.material.seed = 1001;
    if (!fs::exists(other_dir / "material/capture/lights.lp"))
      datasets::GenerateScene(scene, other_dir);
    const HeldOutSplit split = SplitCapture(dir);
    const ptm::RtiCapture &train = split.train, &held = split.held;
    std::vector<cv::Mat> truth, other;
    for (const auto& f : held.files) truth.push_back(ReadRgb(f));
    for (const auto& f : SplitCapture(other_dir).held.files) other.push_back(ReadRgb(f));
    const auto report = [&](const char* label, const auto& relight) {
      double psnr = 0;
      std::vector<cv::Mat> relit;
      for (std::size_t k = 0; k < held.files.size(); ++k) {
        const std::vector<float> rgb = relight(held.lights[k]);
        psnr += Psnr(rgb, truth[k]);
        relit.push_back(AsImage(rgb, truth[k].size()));
      }
      std::printf("  %-22s %.2f dB, gradient distance %.5f\n", label,
                  psnr / static_cast<double>(held.files.size()),
                  MeanGradientDistance(relit, truth));
    };
    std::printf("%s %s capture 256x256, %zu lights fitted, %zu held out (every fourth):\n",
                name.c_str(), realistic ? "realistic" : "clean (no sensor noise)",
                train.files.size(), held.files.size());
    for (const ptm::PtmFormat format : {ptm::PtmFormat::kLrgb, ptm::PtmFormat::kRgb}) {
      ptm::FitOptions o;
      o.format = format;
      const ptm::FitResult r = ptm::FitPtmFromFiles(train.files, train.lights, o);
      report(format == ptm::PtmFormat::kLrgb ? "PTM LRGB" : "PTM RGB",
             [&](const Eigen::Vector3d& l) { return ptm::Relight(r.ptm, l); });
    }
    for (const int order : {2, 3}) {
      const ptm::HshFitResult r = ptm::FitHshFromFiles(train.files, train.lights, order, 32);
      const std::string label = "HSH order " + std::to_string(order) + " (" +
                                std::to_string(ptm::HshTerms(order)) + " terms)";
      report(label.c_str(), [&](const Eigen::Vector3d& l) { return ptm::RelightHsh(r.hsh, l); });
    }
    std::printf("  another instance       gradient distance %.5f\n",
                MeanGradientDistance(other, truth));
  }
}

// Section 4: what the relief's self-shadowing costs a PTM, and what a horizon map
// fitted from the capture alone (ptm/shadowed_fit.h) gives back.
constexpr double kLowLightDeg = 35.0;

double ElevationDeg(const Eigen::Vector3d& l) {
  return std::asin(std::clamp(l.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

cv::Mat TrueHeightTexels(const fs::path& scene_dir) {
  std::ifstream in(scene_dir / "scene.json");
  const double texel_size = nlohmann::json::parse(in)["material"]["texel_size"].get<double>();
  const std::vector<cv::Mat> planes = ptm::ReadExr(scene_dir / "material/ground_truth/height.exr");
  cv::Mat h;
  planes.at(0).convertTo(h, CV_64FC1, 1.0 / texel_size);
  return h;
}

// The bound: the horizon of the true relief, the PTM refitted to the samples it
// leaves lit.
ptm::ShadowedPtm TrueReliefShadowedPtm(const fs::path& scene_dir,
                                       const std::vector<cv::Mat>& images,
                                       const std::vector<Eigen::Vector3d>& lights) {
  const ptm::ShadowedFitOptions o;
  ptm::ShadowedPtm out;
  ptm::SelfShadowing& shadowing = out.shadowing;
  shadowing.penumbra_rad = o.penumbra_deg * std::numbers::pi / 180.0;
  shadowing.horizon =
      ptm::ComputeHorizonMap(TrueHeightTexels(scene_dir), o.sectors, o.reach_texels);
  std::vector<std::vector<float>> lit(lights.size(),
                                      std::vector<float>(shadowing.horizon.NumTexels()));
  for (std::size_t k = 0; k < lights.size(); ++k)
    for (std::size_t t = 0; t < shadowing.horizon.NumTexels(); ++t)
      lit[k][t] =
          ptm::HorizonVisibility(shadowing.horizon, t, lights[k], shadowing.penumbra_rad) > 0.5;
  out.ptm = ptm::FitPtmToLitSamples(images, lights, lit, ptm::PtmFormat::kRgb, o.min_lit_lights);
  // The floor that best fits the capture itself.
  double best = 1e300, best_floor = 0.0;
  for (double f = 0.0; f <= 1.0; f += 0.05) {
    shadowing.shadow_floor = f;
    double error = 0;
    for (std::size_t k = 0; k < lights.size(); ++k)
      error -= Psnr(ptm::RelightShadowed(out, lights[k]), images[k]);
    if (error < best) best = error, best_floor = f;
  }
  shadowing.shadow_floor = best_floor;
  return out;
}

struct HeldOutScore {
  double psnr_all = 0, psnr_low = 0, gradient_all = 0, gradient_low = 0;
  int low = 0;
};

template <typename Relight>
HeldOutScore ScoreHeldOut(const ptm::RtiCapture& held, const std::vector<cv::Mat>& truth,
                          const Relight& relight) {
  HeldOutScore score;
  std::vector<cv::Mat> relit, relit_low, truth_low;
  for (std::size_t k = 0; k < held.files.size(); ++k) {
    const std::vector<float> rgb = relight(held.lights[k]);
    const double psnr = Psnr(rgb, truth[k]);
    relit.push_back(AsImage(rgb, truth[k].size()));
    score.psnr_all += psnr;
    if (ElevationDeg(held.lights[k]) < kLowLightDeg) {
      score.psnr_low += psnr;
      ++score.low;
      relit_low.push_back(relit.back());
      truth_low.push_back(truth[k]);
    }
  }
  score.psnr_all /= static_cast<double>(held.files.size());
  score.gradient_all = MeanGradientDistance(relit, truth);
  if (score.low > 0) {
    score.psnr_low /= score.low;
    score.gradient_low = MeanGradientDistance(relit_low, truth_low);
  }
  return score;
}

void PrintScore(const char* label, const HeldOutScore& s) {
  std::printf("  %-40s %6.2f dB  %.5f   %6.2f dB  %.5f\n", label, s.psnr_all, s.gradient_all,
              s.psnr_low, s.gradient_low);
}

void SelfShadowingSection(const fs::path& work) {
  for (const datasets::MaterialKind kind :
       {datasets::MaterialKind::kStone, datasets::MaterialKind::kBrick,
        datasets::MaterialKind::kGrooves}) {
    datasets::SceneOptions scene = datasets::MaterialOnlySceneOptions(kind, 256, 40);
    datasets::UseRealisticCapture(scene);
    const std::string name(datasets::MaterialKindName(kind));
    const fs::path dir = work / ("hsh_" + name);
    if (!fs::exists(dir / "material/capture/lights.lp")) datasets::GenerateScene(scene, dir);
    const HeldOutSplit split = SplitCapture(dir);
    std::vector<cv::Mat> train_images, truth;
    for (const auto& f : split.train.files) train_images.push_back(ReadRgb(f));
    for (const auto& f : split.held.files) truth.push_back(ReadRgb(f));

    ptm::FitOptions o;
    o.format = ptm::PtmFormat::kRgb;
    const ptm::Ptm plain = ptm::FitPtmFromFiles(split.train.files, split.train.lights, o).ptm;
    o.format = ptm::PtmFormat::kLrgb;
    const ptm::Ptm plain_lrgb = ptm::FitPtmFromFiles(split.train.files, split.train.lights, o).ptm;
    ptm::ShadowedFitOptions shadowed_options;
    shadowed_options.format = ptm::PtmFormat::kRgb;
    const auto t0 = std::chrono::steady_clock::now();
    const ptm::ShadowedPtm fitted =
        ptm::FitShadowedPtm(train_images, split.train.lights, shadowed_options);
    const double fit_seconds = Seconds(t0);
    const ptm::ShadowedPtm fitted_lrgb = ptm::FitShadowedPtm(train_images, split.train.lights);
    const ptm::ShadowedPtm bound = TrueReliefShadowedPtm(dir, train_images, split.train.lights);

    const HeldOutScore base = ScoreHeldOut(
        split.held, truth, [&](const Eigen::Vector3d& l) { return ptm::Relight(plain, l); });
    std::printf(
        "%s realistic capture 256x256, %zu lights fitted, %zu held out (%d below %.0f deg)\n"
        "  %-40s %9s  %7s   %9s  %7s\n",
        name.c_str(), split.train.files.size(), split.held.files.size(), base.low, kLowLightDeg, "",
        "PSNR", "grad", "PSNR low", "grad low");
    PrintScore("PTM RGB", base);
    PrintScore("shadowed PTM, horizon of the true relief",
               ScoreHeldOut(split.held, truth, [&](const Eigen::Vector3d& l) {
                 return ptm::RelightShadowed(bound, l);
               }));
    PrintScore("shadowed PTM fitted from the capture",
               ScoreHeldOut(split.held, truth, [&](const Eigen::Vector3d& l) {
                 return ptm::RelightShadowed(fitted, l);
               }));
    PrintScore("PTM LRGB", ScoreHeldOut(split.held, truth, [&](const Eigen::Vector3d& l) {
                 return ptm::Relight(plain_lrgb, l);
               }));
    PrintScore("shadowed PTM LRGB fitted from the capture",
               ScoreHeldOut(split.held, truth, [&](const Eigen::Vector3d& l) {
                 return ptm::RelightShadowed(fitted_lrgb, l);
               }));
    std::printf(
        "  fitted: height scale %.2f, shadow keeps %.2f of the light, %.1f s (true relief: "
        "%.2f)\n",
        fitted.shadowing.height_scale, fitted.shadowing.shadow_floor, fit_seconds,
        bound.shadowing.shadow_floor);
  }
}

// Section 1: decode + fit + write against decoding alone, LRGB and RGB, the
// decode-only baseline measured before and after the fits (its mean is the ratio's
// denominator: the machine's speed drifts).
void Throughput(int n, cv::Size image_size, const std::string& format, const fs::path& work) {
  std::vector<Eigen::Vector3d> lights;
  std::printf("Preparing %d %s images of %dx%d in %s ...\n", n, format.c_str(), image_size.width,
              image_size.height, work.c_str());
  const auto files =
      ThroughputImages(n, image_size, format,
                       work / ("n" + std::to_string(n) + "_" + std::to_string(image_size.width) +
                               "x" + std::to_string(image_size.height)),
                       &lights);
  const int band_rows = ptm::FitOptions{}.band_rows;
  const double decode_before = DecodeOnly(files, band_rows);
  double full[2], fit_seconds[2];
  for (const ptm::PtmFormat format_out : {ptm::PtmFormat::kLrgb, ptm::PtmFormat::kRgb}) {
    const int f = format_out == ptm::PtmFormat::kLrgb ? 0 : 1;
    ptm::FitOptions options;
    options.format = format_out;
    fs::remove(work / "bench.ptm");  // a new file, as a user's run writes (no old one to free)
    const auto t0 = std::chrono::steady_clock::now();
    const ptm::FitResult fit = ptm::FitPtmFromFiles(files, lights, options);
    ptm::WritePtmFile(fit.ptm, work / "bench.ptm");
    full[f] = Seconds(t0);
    fit_seconds[f] = fit.seconds;
  }
  const double decode_after = DecodeOnly(files, band_rows);
  const double decode_bands = DecodeBands(files, band_rows);
  const double decode = 0.5 * (decode_before + decode_after);
  const double megapixels = image_size.area() / 1e6;
  std::printf("Throughput: %d %s images x %.1f MP\n", n, format.c_str(), megapixels);
  std::printf("  decode only (8-bit, one thread)  %.2f s (%.2f before the fits, %.2f after)\n",
              decode, decode_before, decode_after);
  std::printf("  decode only, every thread (ptm::ImageBands)  %.2f s\n", decode_bands);
  for (int f = 0; f < 2; ++f) {
    std::printf(
        "  %s decode + fit + write  %.2f s  (ratio %.2f; decode + fit %.2f s, write %.2f s; "
        "%.1f M texel-images per second)\n",
        f == 0 ? "LRGB" : "RGB ", full[f], full[f] / decode, fit_seconds[f],
        full[f] - fit_seconds[f], n * megapixels / full[f]);
  }
  std::printf("  peak memory %.0f MiB\n", PeakRssMiB());
  std::printf(
      "  the fit kernel alone, one thread, 8-bit bands in memory: LRGB %.2f ns, RGB %.2f ns per "
      "texel and image (decoding: %.2f ns per pixel)\n",
      KernelNanoseconds(n, image_size.width, ptm::PtmFormat::kLrgb),
      KernelNanoseconds(n, image_size.width, ptm::PtmFormat::kRgb),
      decode * 1e9 / (n * static_cast<double>(image_size.area())));
}

}  // namespace

int main(int argc, char** argv) {
  int n = 50, size = 2048, width = 0, height = 0;
  std::string format = "png", part = "all";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--images")) n = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--size")) size = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--width")) width = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--height")) height = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--format")) format = argv[i + 1];
    if (!std::strcmp(argv[i], "--part")) part = argv[i + 1];
  }
  const fs::path work = fs::temp_directory_path() / "texlume_ptm_bench";
  if (part == "all" || part == "throughput")
    Throughput(n, cv::Size(width > 0 ? width : size, height > 0 ? height : size), format, work);
  if (part == "throughput") return 0;
  if (part == "horizon") {
    SelfShadowingSection(work);
    return 0;
  }

  // Leave-out quality on a synthetic capture.
  const datasets::SceneOptions scene =
      datasets::MaterialOnlySceneOptions(datasets::MaterialKind::kStone, 256, 40);
  const fs::path scene_dir = work / "scene";
  if (!fs::exists(scene_dir / "material/held_out/lights.lp"))
    datasets::GenerateScene(scene, scene_dir);
  const ptm::RtiCapture train =
      ptm::ReadRtiCapture(scene_dir / "material/capture/lights.lp", scene_dir / "material/capture");
  const auto held = sfm::ReadLpFile(scene_dir / "material/held_out/lights.lp");
  for (bool robust : {false, true}) {
    ptm::FitOptions o;
    o.robust = robust;
    const ptm::FitResult r = ptm::FitPtmFromFiles(train.files, train.lights, o);
    double psnr = 0;
    for (const auto& e : held) {
      const cv::Mat image = cv::imread((scene_dir / "material/held_out" / e.filename).string());
      cv::Mat rgb;
      image.convertTo(rgb, CV_32FC3, 1 / 255.0);
      cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
      psnr += Psnr(ptm::Relight(r.ptm, e.direction_in_image), rgb);
    }
    std::printf("Held-out lights (%zu), stone capture 256x256: %s PSNR %.2f dB (fit %.2f s)\n",
                held.size(), robust ? "robust       " : "least squares", psnr / held.size(),
                r.seconds);
  }
  PtmAgainstHsh(work, true);
  PtmAgainstHsh(work, false);
  return 0;
}
