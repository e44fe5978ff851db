// A PTM fitted by texlume relights held-out lights of a capture it has never seen
// at least as well as a plain least-squares reference fit written independently here.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "datasets_synthetic/renderer.h"
#include "datasets_synthetic/scene.h"
#include "ptm/fit.h"
#include "ptm/ptm_io.h"
#include "sfm/lights.h"
#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

ImageRgb LoadDisplay(const std::filesystem::path& path) {
  const cv::Mat bgr = cv::imread(path.string());
  ImageRgb image{bgr.cols, bgr.rows, std::vector<float>(bgr.total() * 3)};
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x)
      for (int c = 0; c < 3; ++c)
        image.pixels[(static_cast<std::size_t>(y) * bgr.cols + x) * 3 +
                     static_cast<std::size_t>(c)] = bgr.at<cv::Vec3b>(y, x)[2 - c] / 255.0f;
  return image;
}

double Psnr(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return 10 * std::log10(1.0 / (sum / static_cast<double>(a.size())));
}

TEST(HeldOut, TexlumeFitRelightsHeldOutLightsAtLeastAsWellAsAReferenceFit) {
  testing::TempDir tmp;
  datasets::GenerateScene(
      datasets::MaterialOnlySceneOptions(datasets::MaterialKind::kBrick, 64, 40), tmp.path());
  const auto held = sfm::ReadLpFile(tmp / "material/held_out/lights.lp");
  const RtiCapture capture =
      ReadRtiCapture(tmp / "material/capture/lights.lp", tmp / "material/capture");
  const std::vector<std::filesystem::path>& files = capture.files;
  const std::vector<Eigen::Vector3d>& lights = capture.lights;
  std::vector<ImageRgb> images;
  for (const auto& f : files) images.push_back(LoadDisplay(f));
  // Reference: per texel and channel, normal equations solved by Eigen.
  Eigen::MatrixXd a(static_cast<Eigen::Index>(lights.size()), 6);
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const double u = lights[k].x(), v = lights[k].y();
    a.row(static_cast<Eigen::Index>(k)) << u * u, v * v, u * v, u, v, 1;
  }
  const Eigen::MatrixXd normal = a.transpose() * a;
  const std::size_t texels = images[0].pixels.size() / 3;
  std::vector<Eigen::Matrix<double, 6, 1>> reference(texels * 3);
  for (std::size_t t = 0; t < texels; ++t) {
    for (int c = 0; c < 3; ++c) {
      Eigen::VectorXd b(static_cast<Eigen::Index>(lights.size()));
      for (std::size_t k = 0; k < lights.size(); ++k)
        b(static_cast<Eigen::Index>(k)) = images[k].pixels[t * 3 + static_cast<std::size_t>(c)];
      reference[t * 3 + static_cast<std::size_t>(c)] = normal.ldlt().solve(a.transpose() * b);
    }
  }
  FitOptions options;
  options.format = PtmFormat::kRgb;
  const FitResult ours = FitPtmFromFiles(files, lights, options);
  // Also through a .ptm file, as a user gets it.
  WritePtmFile(ours.ptm, tmp / "ours.ptm");
  const Ptm from_file = ReadPtmFile(tmp / "ours.ptm");
  for (const auto& e : held) {
    const ImageRgb truth = LoadDisplay(tmp / "material/held_out" / e.filename);
    std::vector<float> ref(truth.pixels.size());
    const double u = e.direction_in_image.x(), v = e.direction_in_image.y();
    Eigen::Matrix<double, 6, 1> basis;
    basis << u * u, v * v, u * v, u, v, 1;
    for (std::size_t i = 0; i < ref.size(); ++i)
      ref[i] = static_cast<float>(std::clamp(reference[i].dot(basis), 0.0, 1.0));
    const double psnr_reference = Psnr(ref, truth.pixels);
    const double psnr_ours = Psnr(Relight(ours.ptm, e.direction_in_image), truth.pixels);
    const double psnr_file = Psnr(Relight(from_file, e.direction_in_image), truth.pixels);
    EXPECT_GE(psnr_ours, psnr_reference - 0.01) << e.filename;
    EXPECT_GE(psnr_file, psnr_reference - 0.3) << e.filename << " after 8-bit quantisation";
    EXPECT_GT(psnr_ours, 20.0) << e.filename;
  }
}

}  // namespace
}  // namespace texlume::ptm
