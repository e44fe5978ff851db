#include "ptm/fit.h"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <omp.h>

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <iterator>
#include <map>
#include <memory>
#include <thread>

#include "core/check.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "ptm/image_bands.h"
#include "ptm/least_squares_bands.h"
#include "ptm/ptm_sample_cost.h"
#include "sfm/lights.h"

namespace texlume::ptm {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using MatrixX6 = Eigen::Matrix<double, Eigen::Dynamic, 6>;

// Robust refinement of one polynomial from its samples (Cauchy loss), starting
// from the least-squares coefficients in `a`.
void RobustRefine(const MatrixX6& basis, const std::vector<double>& values,
                  const std::vector<char>& usable, double scale, double* a) {
  std::size_t count = 0;
  for (char u : usable) count += u ? 1 : 0;
  if (count < 6) return;
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(scale);
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!usable[k]) continue;
    std::array<double, 6> b;
    for (int i = 0; i < 6; ++i)
      b[static_cast<std::size_t>(i)] = basis(static_cast<Eigen::Index>(k), i);
    problem.AddResidualBlock(new PtmSampleCost(b, values[k]), &loss, a);
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = 25;
  solver_options.logging_type = ceres::SILENT;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
}

// The robust fit of every texel of a band (FitOptions::robust): least squares over
// the usable samples, then the Cauchy loss (RobustRefine). pixels[k] holds the band
// of image k (rows x width x 3, [0, 1]).
class RobustBandFitter {
 public:
  RobustBandFitter(const std::vector<Eigen::Vector3d>& lights, const FitOptions& options)
      : options_(options), basis_(PtmLightMatrix(lights)) {
    pseudo_inverse_ = basis_.completeOrthogonalDecomposition().pseudoInverse();
  }

  void Fit(const std::vector<const float*>& pixels, int rows, int width, int first_row, Ptm& ptm,
           std::vector<float>& residual) const {
    const long texels = static_cast<long>(rows) * width;
    // On every thread, unless called from ImageBands' tasks (already on every thread).
#pragma omp parallel if (!omp_in_parallel())
    {
      // Per-thread buffers, reused for every texel (no allocation in the loop).
      Texel texel_buffers(pixels.size());
#pragma omp for schedule(dynamic, 256)
      for (long t = 0; t < texels; ++t) {
        const std::size_t local = static_cast<std::size_t>(t);
        const std::size_t texel =
            static_cast<std::size_t>(first_row) * static_cast<std::size_t>(width) + local;
        Load(pixels, local, texel_buffers);
        residual[texel] = static_cast<float>(FitTexel(texel_buffers, texel, ptm));
      }
    }
  }

 private:
  struct Texel {
    explicit Texel(std::size_t k_count) : rgb(k_count), usable(k_count, 1), values(k_count) {}
    std::vector<Eigen::Vector3d> rgb;
    std::vector<char> usable;
    std::vector<double> values;
  };

  void Load(const std::vector<const float*>& pixels, std::size_t local, Texel& t) const {
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      const float* p = pixels[k] + local * 3;
      t.rgb[k] = Eigen::Vector3d(p[0], p[1], p[2]);
      t.usable[k] = t.rgb[k].maxCoeff() < options_.saturation_threshold &&
                    t.rgb[k].maxCoeff() > options_.shadow_threshold;
    }
  }

  // Fits one texel; returns its residual RMS over lights and channels.
  double FitTexel(Texel& t, std::size_t texel, Ptm& ptm) const {
    const std::size_t k_count = t.rgb.size();
    double sum_sq = 0.0;
    if (ptm.format == PtmFormat::kLrgb) {
      // Chromaticity: luminance-weighted mean colour of the usable samples, largest 1.
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < k_count; ++k) {
        if (t.usable[k]) c += t.rgb[k].mean() * t.rgb[k];
      }
      c = c.maxCoeff() > 1e-9 ? Eigen::Vector3d(c / c.maxCoeff()) : Eigen::Vector3d::Ones();
      const Eigen::Vector3d c_scaled = c / c.squaredNorm();
      for (std::size_t k = 0; k < k_count; ++k) t.values[k] = t.rgb[k].dot(c_scaled);
      double a[6];
      SolveRobust(t, a);
      float* out = ptm.Coefficients(texel);
      for (int i = 0; i < 6; ++i) out[i] = static_cast<float>(a[i]);
      for (int ch = 0; ch < 3; ++ch)
        ptm.colour[texel * 3 + static_cast<std::size_t>(ch)] = static_cast<float>(c[ch]);
      for (std::size_t k = 0; k < k_count; ++k)
        sum_sq += (Predict(k, a) * c - t.rgb[k]).squaredNorm();
    } else {
      for (int ch = 0; ch < 3; ++ch) {
        for (std::size_t k = 0; k < k_count; ++k) t.values[k] = t.rgb[k][ch];
        double a[6];
        SolveRobust(t, a);
        float* out = ptm.Coefficients(texel, ch);
        for (int i = 0; i < 6; ++i) out[i] = static_cast<float>(a[i]);
        for (std::size_t k = 0; k < k_count; ++k) {
          const double d = Predict(k, a) - t.values[k];
          sum_sq += d * d;
        }
      }
    }
    return ResidualRms(sum_sq, k_count);
  }

  // Least squares a = A^+ values (one 6 x N product), then the Cauchy loss.
  void SolveRobust(const Texel& t, double* a) const {
    for (int i = 0; i < 6; ++i) {
      double sum = 0.0;
      for (std::size_t k = 0; k < t.values.size(); ++k) {
        sum += pseudo_inverse_(i, static_cast<Eigen::Index>(k)) * t.values[k];
      }
      a[i] = sum;
    }
    RobustRefine(basis_, t.values, t.usable, options_.robust_scale, a);
  }
  double Predict(std::size_t k, const double* a) const {
    double v = 0.0;
    for (int i = 0; i < 6; ++i) v += basis_(static_cast<Eigen::Index>(k), i) * a[i];
    return v;
  }

  const FitOptions& options_;
  MatrixX6 basis_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> pseudo_inverse_;
};

// The least-squares fit of every band of `bands` into `result`, the samples read as
// Sample (`unit` per 1) in planes.
template <typename Sample>
void FitLeastSquares(ImageBands& bands, const std::vector<Eigen::Vector3d>& lights, double unit,
                     int band_rows, const ProgressCallback& progress, FitResult& result) {
  const LeastSquaresBands fitter(lights);
  bands.ForEach<Sample>(
      band_rows,
      [&](const std::vector<const Sample*>& pixels, int y0, int rows) {
        fitter.Fit(pixels, unit, rows, bands.width(), y0, result.ptm, result.residual_rms);
      },
      progress, "fit", BandLayout::kRowPlanar);
}

// Each image's rows as their R, G and B values (BandLayout::kRowPlanar).
std::vector<std::vector<float>> PlanesOf(const std::vector<ImageRgb>& images) {
  std::vector<std::vector<float>> planes;
  for (const auto& image : images) {
    const auto width = static_cast<std::size_t>(image.width);
    std::vector<float>& out = planes.emplace_back(image.pixels.size());
    for (std::size_t t = 0; t < image.pixels.size() / 3; ++t)
      for (std::size_t ch = 0; ch < 3; ++ch)
        out[((t / width) * 3 + ch) * width + t % width] = image.pixels[t * 3 + ch];
  }
  return planes;
}

void Finish(FitResult& result, std::chrono::steady_clock::time_point start) {
  double sum = 0.0;
  for (float r : result.residual_rms) sum += r;
  result.mean_residual_rms =
      result.residual_rms.empty() ? 0.0 : sum / static_cast<double>(result.residual_rms.size());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void FitOptions::Check() const {
  if (!(robust_scale > 0.0 && robust_scale <= 1.0))
    throw OptionError("robust_scale must be in (0, 1]");
  if (!(saturation_threshold > 0.0 && saturation_threshold <= 1.0)) {
    throw OptionError("saturation_threshold must be in (0, 1]");
  }
  if (!(shadow_threshold >= 0.0 && shadow_threshold < 1.0)) {
    throw OptionError("shadow_threshold must be in [0, 1)");
  }
  if (band_rows < 1) throw OptionError("band_rows must be >= 1");
  if (min_lights < 6) throw OptionError("min_lights must be >= 6");
  if (!(max_condition_number > 1.0)) throw OptionError("max_condition_number must be > 1");
}

void CheckLightSet(const std::vector<Eigen::Vector3d>& lights, const FitOptions& options,
                   const std::string& label) {
  options.Check();
  CheckLightsForBasis(lights, PtmLightMatrix(lights), static_cast<std::size_t>(options.min_lights),
                      options.max_condition_number, "a PTM", label);
}

void CheckLightsForBasis(const std::vector<Eigen::Vector3d>& lights,
                         const Eigen::MatrixXd& basis_rows, std::size_t min_lights,
                         double max_condition_number, const std::string& basis,
                         const std::string& label) {
  TEXLUME_CHECK(basis_rows.rows() == static_cast<Eigen::Index>(lights.size()) &&
                    basis_rows.cols() >= 1 &&
                    min_lights >= static_cast<std::size_t>(basis_rows.cols()),
                "a row of the basis per light, at least as many lights as terms");
  if (lights.size() < min_lights) {
    throw InputError(label, std::to_string(lights.size()) + " usable lights; " + basis +
                                " needs at least " + std::to_string(min_lights));
  }
  for (std::size_t k = 0; k < lights.size(); ++k) {
    if (!lights[k].allFinite() || std::abs(lights[k].norm() - 1.0) > 1e-6) {
      throw InputError(label, "light " + std::to_string(k) + " is not a unit vector");
    }
    if (!(lights[k].z() > 0.0)) {
      throw InputError(label,
                       "light " + std::to_string(k) + " is at or below the horizon (z <= 0)");
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(basis_rows);
  const auto s = svd.singularValues();
  const Eigen::Index last = s.size() - 1;
  const double condition = s(last) > 0 ? (s(0) / s(last)) * (s(0) / s(last)) : INFINITY;
  if (!(condition <= max_condition_number)) {
    throw InputError(label, "degenerate light set for " + basis +
                                ": the normal equations are singular (condition " +
                                std::to_string(condition) +
                                "); spread the lights over the dome in azimuth and elevation");
  }
}

namespace {

// The files of a capture folder by their lower-case names, read once.
class CaptureFolder {
 public:
  explicit CaptureFolder(std::filesystem::path dir) : dir_(std::move(dir)) {}

  // The file the .lp means by `name`: its exact name, else the one equal ignoring case.
  std::filesystem::path Find(const std::string& name, const std::filesystem::path& lp_path,
                             std::vector<std::string>& warnings) {
    std::error_code ec;
    const std::filesystem::path exact = dir_ / name;
    if (std::filesystem::is_regular_file(exact, ec)) return exact;
    const auto [first, last] = ByLowerCaseName().equal_range(LowerCase(name));
    if (first == last) {
      throw InputError(lp_path.string(),
                       "names '" + name + "', but " + exact.string() + " does not exist");
    }
    if (std::next(first) != last) {
      throw InputError(lp_path.string(), "names '" + name + "', which is not in " + dir_.string() +
                                             "; several files match it ignoring case");
    }
    warnings.push_back(lp_path.string() + " names '" + name + "'; using " +
                       first->second.filename().string() +
                       ", the one file of that name ignoring case");
    return first->second;
  }

 private:
  const std::multimap<std::string, std::filesystem::path>& ByLowerCaseName() {
    if (listed_) return by_lower_case_name_;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
      if (entry.is_regular_file(ec))
        by_lower_case_name_.emplace(LowerCase(entry.path().filename().string()), entry.path());
    }
    listed_ = true;
    return by_lower_case_name_;
  }

  std::filesystem::path dir_;
  bool listed_ = false;
  std::multimap<std::string, std::filesystem::path> by_lower_case_name_;
};

}  // namespace

RtiCapture ReadRtiCapture(const std::filesystem::path& lp_path,
                          const std::filesystem::path& images_dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(images_dir, ec)) {
    throw InputError(images_dir.string(), "image folder not found");
  }
  RtiCapture capture;
  CaptureFolder folder(images_dir);
  for (const auto& e : sfm::ReadLpFile(lp_path)) {
    capture.files.push_back(folder.Find(sfm::BaseName(e.filename), lp_path, capture.warnings));
    capture.lights.push_back(e.direction_in_image);
  }
  return capture;
}

FitResult FitPtm(const std::vector<ImageRgb>& images, const std::vector<Eigen::Vector3d>& lights,
                 const FitOptions& options, const std::string& label) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  if (images.size() != lights.size()) {
    throw InputError(label, std::to_string(images.size()) + " images but " +
                                std::to_string(lights.size()) + " lights");
  }
  CheckLightSet(lights, options, label);
  const int width = images[0].width, height = images[0].height;
  for (std::size_t k = 0; k < images.size(); ++k) {
    if (images[k].width != width || images[k].height != height ||
        images[k].pixels.size() != static_cast<std::size_t>(width) * height * 3) {
      throw InputError(label, "image " + std::to_string(k) + " differs in size from image 0");
    }
  }
  FitResult result;
  result.ptm.Resize(options.format, width, height);
  result.residual_rms.assign(result.ptm.NumTexels(), 0.0f);
  result.num_images = images.size();
  std::vector<const float*> pixels;
  if (options.robust) {
    for (const auto& image : images) pixels.push_back(image.pixels.data());
    RobustBandFitter(lights, options)
        .Fit(pixels, height, width, 0, result.ptm, result.residual_rms);
  } else {
    const std::vector<std::vector<float>> planes = PlanesOf(images);
    for (const auto& image : planes) pixels.push_back(image.data());
    LeastSquaresBands(lights).Fit(pixels, 1.0, height, width, 0, result.ptm, result.residual_rms);
  }
  Finish(result, start);
  return result;
}

FitResult FitPtmFromFiles(const std::vector<std::filesystem::path>& files,
                          const std::vector<Eigen::Vector3d>& lights, const FitOptions& options,
                          const ProgressCallback& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  TEXLUME_CHECK(files.size() == lights.size(), "one light per file");
  const std::string label = files.empty() ? "images" : files[0].parent_path().string();
  CheckLightSet(lights, options, label);
  ImageBands bands(files);
  FitResult result;
  result.ptm.Resize(options.format, bands.width(), bands.height());
  result.residual_rms.assign(result.ptm.NumTexels(), 0.0f);
  result.num_images = files.size();
  if (options.robust) {
    const RobustBandFitter fitter(lights, options);
    bands.ForEach<float>(
        options.band_rows,
        [&](const std::vector<const float*>& pixels, int y0, int rows) {
          fitter.Fit(pixels, rows, bands.width(), y0, result.ptm, result.residual_rms);
        },
        progress, "fit");
  } else if (bands.eight_bit()) {  // the camera's own bytes: no conversion on the way
    FitLeastSquares<std::uint8_t>(bands, lights, 255.0, options.band_rows, progress, result);
  } else {
    FitLeastSquares<float>(bands, lights, 1.0, options.band_rows, progress, result);
  }
  Finish(result, start);
  return result;
}

FitResult FitPtmPerTexelLights(
    const std::vector<ImageRgb>& images,
    const std::function<Eigen::Vector3d(int image, int x, int y)>& light_at,
    const FitOptions& options) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  TEXLUME_CHECK(!images.empty(), "a fit needs images");
  const int width = images[0].width, height = images[0].height;
  FitResult result;
  result.ptm.Resize(options.format, width, height);
  result.residual_rms.assign(result.ptm.NumTexels(), 0.0f);
  result.num_images = images.size();
#pragma omp parallel for schedule(dynamic, 16)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t texel = static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x);
      std::vector<Eigen::Vector3d> lights, rgb;
      for (std::size_t k = 0; k < images.size(); ++k) {
        const Eigen::Vector3d l = light_at(static_cast<int>(k), x, y);
        if (!(l.z() > 0.0)) continue;
        lights.push_back(l.normalized());
        const float* p = images[k].pixels.data() + texel * 3;
        rgb.emplace_back(p[0], p[1], p[2]);
      }
      Matrix6 normal = Matrix6::Zero();
      const MatrixX6 a = PtmLightMatrix(lights);
      normal = a.transpose() * a;
      const Eigen::JacobiSVD<Matrix6> svd(normal);
      const bool solvable =
          lights.size() >= 6 &&
          svd.singularValues()(5) * options.max_condition_number > svd.singularValues()(0);
      Eigen::Vector3d c = Eigen::Vector3d::Ones();
      if (options.format == PtmFormat::kLrgb) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (const auto& v : rgb) sum += v.mean() * v;
        c = sum.maxCoeff() > 1e-9 ? Eigen::Vector3d(sum / sum.maxCoeff()) : Eigen::Vector3d::Ones();
        for (int ch = 0; ch < 3; ++ch)
          result.ptm.colour[texel * 3 + static_cast<std::size_t>(ch)] = static_cast<float>(c[ch]);
      }
      double sum_sq = 0.0;
      for (int poly = 0; poly < result.ptm.NumPolynomials(); ++poly) {
        Eigen::VectorXd v(static_cast<Eigen::Index>(rgb.size()));
        for (std::size_t k = 0; k < rgb.size(); ++k) {
          v(static_cast<Eigen::Index>(k)) =
              options.format == PtmFormat::kLrgb ? rgb[k].dot(c) / c.squaredNorm() : rgb[k][poly];
        }
        Eigen::Matrix<double, 6, 1> coef = Eigen::Matrix<double, 6, 1>::Zero();
        if (solvable) {
          coef = normal.ldlt().solve(a.transpose() * v);  // normal equations
        } else if (v.size() > 0) {
          coef[5] = v.mean();
        }
        float* out = result.ptm.Coefficients(texel, poly);
        for (int i = 0; i < 6; ++i) out[i] = static_cast<float>(coef[i]);
        if (v.size() > 0) sum_sq += (a * coef - v).squaredNorm();
      }
      result.residual_rms[texel] =
          rgb.empty() ? 0.0f
                      : static_cast<float>(std::sqrt(sum_sq / (static_cast<double>(rgb.size()) *
                                                               result.ptm.NumPolynomials())));
    }
  }
  Finish(result, start);
  return result;
}

}  // namespace texlume::ptm
