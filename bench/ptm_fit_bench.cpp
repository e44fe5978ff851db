// PTM fitting benchmarks (issue 4). Run: build/bench/ptm_fit_bench [--images N] [--size S]
// 1. Throughput: N synthetic RTI images of S x S pixels (default 50 of 2048 x 2048,
//    4.2 MP) are written as PNG once, then in one run: decoding every band of every
//    image alone (the baseline), and decode + least-squares fit + .ptm write.
//    Reports the ratio and the process's peak memory (run with two values of N to
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
#include <OpenImageIO/imageio.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "datasets_synthetic/renderer.h"
#include "datasets_synthetic/scene.h"
#include "ptm/fit.h"
#include "ptm/hsh.h"
#include "ptm/ptm_io.h"
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

// Writes (once) n images of a smooth random PTM relit at dome lights.
std::vector<fs::path> ThroughputImages(int n, int size, const fs::path& dir,
                                       std::vector<Eigen::Vector3d>* lights) {
  *lights = datasets::DomeLights(n, 15, 80, 0.0);
  fs::create_directories(dir);
  std::vector<fs::path> files;
  cv::Mat a[6];
  std::mt19937 rng(1);
  for (int i = 0; i < 6; ++i) {
    cv::Mat small(16, 16, CV_32FC1);
    cv::randu(small, -0.25, 0.25);
    cv::resize(small, a[i], cv::Size(size, size), 0, 0, cv::INTER_CUBIC);
  }
  for (int k = 0; k < n; ++k) {
    files.push_back(dir / ("img_" + std::to_string(k) + ".png"));
    if (fs::exists(files.back())) continue;
    const auto b = ptm::PtmBasis((*lights)[static_cast<std::size_t>(k)].x(),
                                 (*lights)[static_cast<std::size_t>(k)].y());
    cv::Mat image(size, size, CV_8UC3);
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        double l = 0.55;
        for (int i = 0; i < 6; ++i) l += b[static_cast<std::size_t>(i)] * a[i].at<float>(y, x);
        const auto v = static_cast<std::uint8_t>(std::clamp(std::lround(255 * l), 0L, 255L));
        image.at<cv::Vec3b>(y, x) =
            cv::Vec3b(v, static_cast<std::uint8_t>(v * 0.9), static_cast<std::uint8_t>(v * 0.8));
      }
    }
    cv::imwrite(files.back().string(), image);
  }
  return files;
}

double DecodeOnly(const std::vector<fs::path>& files, int band_rows) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::unique_ptr<OIIO::ImageInput>> inputs;
  for (const auto& f : files) inputs.push_back(OIIO::ImageInput::open(f.string()));
  const int width = inputs[0]->spec().width, height = inputs[0]->spec().height;
  std::vector<float> band(static_cast<std::size_t>(band_rows) * width * 3);
  double checksum = 0;
  for (int y0 = 0; y0 < height; y0 += band_rows) {
    const int rows = std::min(band_rows, height - y0);
    for (auto& in : inputs) {
      in->read_scanlines(0, 0, y0, y0 + rows, 0, 0, 3, OIIO::TypeDesc::FLOAT, band.data());
      checksum += band[0];
    }
  }
  if (checksum < 0) std::printf("impossible\n");
  return Seconds(t0);
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

}  // namespace

int main(int argc, char** argv) {
  int n = 50, size = 2048;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--images")) n = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--size")) size = std::atoi(argv[i + 1]);
  }
  const fs::path work = fs::temp_directory_path() / "texlume_ptm_bench";
  std::vector<Eigen::Vector3d> lights;
  std::printf("Preparing %d images of %dx%d in %s ...\n", n, size, size, work.c_str());
  const auto files = ThroughputImages(
      n, size, work / ("n" + std::to_string(n) + "_" + std::to_string(size)), &lights);
  ptm::FitOptions options;
  const double decode = DecodeOnly(files, options.band_rows);
  const auto t0 = std::chrono::steady_clock::now();
  const ptm::FitResult fit = ptm::FitPtmFromFiles(files, lights, options);
  ptm::WritePtmFile(fit.ptm, work / "bench.ptm");
  const double full = Seconds(t0);
  const double megapixels = size * static_cast<double>(size) / 1e6;
  std::printf("Throughput: %d images x %.1f MP\n", n, megapixels);
  std::printf("  decode only            %.2f s\n", decode);
  std::printf(
      "  decode + fit + write   %.2f s  (ratio %.2f, fit+write add %.0f %%; of which decode + fit "
      "%.2f s, write %.2f s)\n",
      full, full / decode, 100 * (full / decode - 1), fit.seconds, full - fit.seconds);
  std::printf(
      "  %.1f M texel-images per second; peak memory %.0f MiB (output PTM %.0f MiB)\n",
      n * megapixels / full, PeakRssMiB(),
      fit.ptm.coefficients.size() * 4.0 / (1 << 20) + fit.ptm.colour.size() * 4.0 / (1 << 20));

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
