// Image-constrained planar PTM synthesis (issue 5, paper 003 Algorithm 1 and Fig. 3).
// Run: build/bench/synth2d_bench [--material stone|brick|grooves] [--size N] [--scale R]
// A 256x256 stone sample PTM is fitted to a synthetic RTI capture; a 512x512 surface
// of the same material (unseen by the capture) is photographed at 256x256 under 3
// lights; PTM_out is synthesised with photo constraints (blend and seam cut) and
// without (classic quilting), and compared with ground truth rendered at 512x512
// under the photos' lights and 6 held-out lights, against bicubic upscaling of the
// photos. Also times the FFT candidate search against the brute-force reference.
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "datasets_synthetic/renderer.h"
#include "datasets_synthetic/scene.h"
#include "ptm/fit.h"
#include "sfm/lights.h"
#include "synth/mesh_synthesis.h"
#include "synth/planar_synthesis.h"
#include "synth/template_match.h"

using namespace texlume;
namespace fs = std::filesystem;

namespace {

cv::Mat ToFloatRgb(const cv::Mat& bgr8) {
  cv::Mat f;
  bgr8.convertTo(f, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(f, f, cv::COLOR_BGR2RGB);
  return f;
}

cv::Mat RelitMat(const ptm::Ptm& p, const Eigen::Vector3d& light) {
  const std::vector<float> v = ptm::Relight(p, light);
  return cv::Mat(p.height, p.width, CV_32FC3, const_cast<float*>(v.data())).clone();
}

double Psnr(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  d = d.mul(d);
  const cv::Scalar s = cv::mean(d);
  return 10 * std::log10(1.0 / ((s[0] + s[1] + s[2]) / 3.0));
}

}  // namespace

int main(int argc, char** argv) {
  std::string material = "stone";
  int size = 512, scale = 2, block = 32, overlap = 8, top_k = 12;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--material")) material = argv[i + 1];
    if (!std::strcmp(argv[i], "--size")) size = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--scale")) scale = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--block")) block = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--overlap")) overlap = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--top-k")) top_k = std::atoi(argv[i + 1]);
  }
  const fs::path work = fs::temp_directory_path() / ("texlume_synth2d_" + material);
  const datasets::SceneOptions scene =
      datasets::MaterialOnlySceneOptions(*datasets::MaterialKindFromName(material), 256, 40);
  if (!fs::exists(work / "material/capture/lights.lp")) datasets::GenerateScene(scene, work);
  const ptm::RtiCapture capture =
      ptm::ReadRtiCapture(work / "material/capture/lights.lp", work / "material/capture");
  const ptm::Ptm sample = ptm::FitPtmFromFiles(capture.files, capture.lights, {}).ptm;

  const std::vector<Eigen::Vector3d> photo_lights = {
      Eigen::Vector3d(0.6, 0.2, 0.77).normalized(), Eigen::Vector3d(-0.4, 0.5, 0.77).normalized(),
      Eigen::Vector3d(-0.1, -0.65, 0.75).normalized()};
  const auto held_lights = datasets::DomeLights(6, 25, 70, 0.3);
  std::vector<Eigen::Vector3d> truth_lights = photo_lights;
  truth_lights.insert(truth_lights.end(), held_lights.begin(), held_lights.end());
  datasets::PlanarSurfaceOptions surface;
  surface.material = scene.material;
  surface.size = size;
  surface.scale = scale;
  const datasets::PlanarSurfaceRenders renders =
      datasets::RenderPlanarSurface(surface, photo_lights, truth_lights);
  std::vector<synth::PlanarPhoto> photos;
  for (std::size_t n = 0; n < photo_lights.size(); ++n) {
    const cv::Mat f = ToFloatRgb(renders.photos[n]);
    synth::PlanarPhoto p;
    p.image = {f.cols, f.rows, std::vector<float>(f.begin<float>(), f.end<float>())};
    p.image.pixels.assign(reinterpret_cast<const float*>(f.data),
                          reinterpret_cast<const float*>(f.data) + f.total() * 3);
    p.light = photo_lights[n];
    p.name = "photo_" + std::to_string(n);
    photos.push_back(p);
  }
  std::printf("%s: sample PTM %dx%d, PTM_out %dx%d from %zu photos of %dx%d\n", material.c_str(),
              sample.width, sample.height, size, size, photos.size(), size / scale, size / scale);

  struct Variant {
    const char* name;
    bool photos;
    synth::Stitch stitch;
    int correction_iterations;
  };
  const Variant variants[] = {
      {"constrained, blend, quilting only (paper)", true, synth::Stitch::kBlend, 0},
      {"constrained, seam cut, quilting only     ", true, synth::Stitch::kSeamCut, 0},
      {"constrained, blend + photo consistency   ", true, synth::Stitch::kBlend, 2},
      {"constrained, seam cut + photo consistency", true, synth::Stitch::kSeamCut, 2},
      {"unconstrained, blend                     ", false, synth::Stitch::kBlend, 0}};
  for (const Variant& v : variants) {
    synth::PlanarSynthesisOptions o;
    o.use_photos = v.photos;
    o.stitch = v.stitch;
    o.width = o.height = size;
    o.block_size = block;
    o.overlap = overlap;
    o.top_k = top_k;
    o.correction_iterations = v.correction_iterations;
    const auto r = synth::SynthesizePlanarPtm(
        sample, v.photos ? photos : std::vector<synth::PlanarPhoto>{}, o);
    double psnr_photos = 0, psnr_full_photo_lights = 0, psnr_held = 0;
    for (std::size_t n = 0; n < photos.size(); ++n) {
      cv::Mat relit = RelitMat(r.ptm, photo_lights[n]) * (v.photos ? r.photo_gains[n] : 1.0), small;
      cv::resize(relit, small, cv::Size(size / scale, size / scale), 0, 0, cv::INTER_AREA);
      psnr_photos += Psnr(small, ToFloatRgb(renders.photos[n])) / photos.size();
      psnr_full_photo_lights +=
          Psnr(RelitMat(r.ptm, photo_lights[n]), ToFloatRgb(renders.truth[n])) / photos.size();
    }
    for (std::size_t h = 0; h < held_lights.size(); ++h) {
      psnr_held +=
          Psnr(RelitMat(r.ptm, held_lights[h]), ToFloatRgb(renders.truth[photos.size() + h])) /
          held_lights.size();
    }
    std::printf(
        "  %s: %.2f s; PSNR vs photos %.2f dB, vs truth at photo lights %.2f dB, at held-out "
        "lights %.2f dB; "
        "seam cost %.5f per seam texel; nearest-patch energy %.5f\n",
        v.name, r.seconds, psnr_photos, psnr_full_photo_lights, psnr_held, r.seam_cost_per_texel,
        synth::NearestPatchEnergy(r.ptm, sample, 16));
  }
  double bicubic = 0;
  for (std::size_t n = 0; n < photos.size(); ++n) {
    cv::Mat up;
    cv::resize(ToFloatRgb(renders.photos[n]), up, cv::Size(size, size), 0, 0, cv::INTER_CUBIC);
    bicubic += Psnr(up, ToFloatRgb(renders.truth[n])) / photos.size();
  }
  // Relightable bicubic baselines for the held-out lights: (a) the photo whose
  // light is nearest, upscaled; (b) Lambertian photometric stereo on the photos
  // (linear domain, per channel, exact with 3 lights), upscaled, relit.
  auto to_linear = [](cv::Mat m) {
    for (float* p = m.ptr<float>(); p != m.ptr<float>() + m.total() * 3; ++p) *p = SrgbToLinear(*p);
    return m;
  };
  auto to_srgb = [](cv::Mat m) {
    for (float* p = m.ptr<float>(); p != m.ptr<float>() + m.total() * 3; ++p) *p = LinearToSrgb(*p);
    return m;
  };
  std::vector<cv::Mat> up_linear;
  for (std::size_t n = 0; n < photos.size(); ++n) {
    cv::Mat up;
    cv::resize(ToFloatRgb(renders.photos[n]), up, cv::Size(size, size), 0, 0, cv::INTER_CUBIC);
    up_linear.push_back(to_linear(up.clone()));
  }
  Eigen::MatrixXd light_matrix(static_cast<int>(photos.size()), 3);
  for (std::size_t n = 0; n < photos.size(); ++n)
    light_matrix.row(static_cast<int>(n)) = photo_lights[n].transpose();
  const Eigen::MatrixXd pseudo_inverse =
      (light_matrix.transpose() * light_matrix).inverse() * light_matrix.transpose();
  double nearest_held = 0, lambert_held = 0;
  for (std::size_t h = 0; h < held_lights.size(); ++h) {
    const cv::Mat truth = ToFloatRgb(renders.truth[photos.size() + h]);
    std::size_t nearest = 0;
    for (std::size_t n = 1; n < photos.size(); ++n)
      if (photo_lights[n].dot(held_lights[h]) > photo_lights[nearest].dot(held_lights[h]))
        nearest = n;
    cv::Mat up;
    cv::resize(ToFloatRgb(renders.photos[nearest]), up, cv::Size(size, size), 0, 0,
               cv::INTER_CUBIC);
    nearest_held += Psnr(up, truth) / held_lights.size();
    cv::Mat lambert(size, size, CV_32FC3);
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        for (int c = 0; c < 3; ++c) {
          Eigen::VectorXd i(static_cast<int>(photos.size()));
          for (std::size_t n = 0; n < photos.size(); ++n)
            i[static_cast<int>(n)] = up_linear[n].at<cv::Vec3f>(y, x)[c];
          const Eigen::Vector3d b = pseudo_inverse * i;  // albedo x normal
          lambert.at<cv::Vec3f>(y, x)[c] = static_cast<float>(std::max(0.0, b.dot(held_lights[h])));
        }
      }
    }
    lambert_held += Psnr(to_srgb(lambert), truth) / held_lights.size();
  }
  std::printf(
      "  bicubic upscale of the photos: PSNR vs truth at photo lights %.2f dB; at held-out lights: "
      "nearest-light photo %.2f dB, Lambertian photometric stereo %.2f dB\n",
      bicubic, nearest_held, lambert_held);

  // Ceiling of any PTM: a PTM fitted to ground truth at full resolution under 40
  // dome lights, relit at the held-out lights.
  {
    const auto fit_lights = datasets::DomeLights(40, 15, 80, 0.0);
    const auto fit_renders = datasets::RenderPlanarSurface(surface, {}, fit_lights);
    std::vector<ptm::ImageRgb> images;
    for (const cv::Mat& t : fit_renders.truth) {
      const cv::Mat f = ToFloatRgb(t);
      images.push_back(
          {f.cols, f.rows,
           std::vector<float>(reinterpret_cast<const float*>(f.data),
                              reinterpret_cast<const float*>(f.data) + f.total() * 3)});
    }
    const ptm::Ptm oracle = ptm::FitPtm(images, fit_lights, {}).ptm;
    double oracle_held = 0;
    for (std::size_t h = 0; h < held_lights.size(); ++h)
      oracle_held +=
          Psnr(RelitMat(oracle, held_lights[h]), ToFloatRgb(renders.truth[photos.size() + h])) /
          held_lights.size();
    std::printf(
        "  ceiling: PTM fitted to the ground truth under 40 lights, at held-out lights %.2f dB\n",
        oracle_held);
  }

  // FFT vs brute force for one candidate search (all positions, 32x32 template, 6 planes).
  const auto planes = synth::ToOrthonormalPlanes(sample);
  const std::vector<cv::Mat> coefficients(planes.begin(), planes.begin() + 6);
  std::vector<cv::Mat> templ;
  for (const auto& p : coefficients) templ.push_back(p(cv::Rect(40, 40, 32, 32)).clone());
  cv::Mat mask = cv::Mat::zeros(32, 32, CV_32FC1);
  mask(cv::Rect(0, 0, 8, 32)).setTo(1.0f);
  mask(cv::Rect(0, 24, 32, 8)).setTo(1.0f);
  const cv::Mat energy = synth::PlaneEnergy(coefficients);
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 5; ++i) synth::MaskedSsd(coefficients, energy, templ, mask);
  const double fft =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 5;
  t0 = std::chrono::steady_clock::now();
  synth::MaskedSsdBruteForce(coefficients, templ, mask);
  const double brute = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "Candidate search over all %dx%d positions: FFT %.2f ms, brute force %.1f ms (%.0fx)\n",
      sample.width - 31, sample.height - 31, fft * 1e3, brute * 1e3, brute / fft);
  return 0;
}
