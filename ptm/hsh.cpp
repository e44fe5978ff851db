#include "ptm/hsh.h"

#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/timing.h"
#include "ptm/fit.h"
#include "ptm/image_bands.h"
#include "ptm/light_response.h"
#include "ptm/ptm.h"
#include "ptm/ptm_io.h"

namespace texlume::ptm {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Light sets whose normal matrix for the basis has a larger condition number are degenerate.
constexpr double kMaxConditionNumber = 1e7;

using BasisMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Row k: the first `terms` basis functions at light k.
BasisMatrix BasisRows(const std::vector<Eigen::Vector3d>& lights, int terms) {
  BasisMatrix a(static_cast<Eigen::Index>(lights.size()), terms);
  for (std::size_t k = 0; k < lights.size(); ++k) {
    const std::array<double, 9> b = HshBasis(lights[k]);
    for (int j = 0; j < terms; ++j)
      a(static_cast<Eigen::Index>(k), j) = b[static_cast<std::size_t>(j)];
  }
  return a;
}

// Per term, over texels and channels: value = byte / 255 * scale + bias (the .rti convention).
struct TermQuantiser {
  std::vector<float> scale, bias;
  explicit TermQuantiser(const Hsh& hsh)
      : scale(static_cast<std::size_t>(hsh.Terms()), 1.0f), bias(scale.size(), 0.0f) {
    for (int j = 0; j < hsh.Terms(); ++j) {
      float lo = INFINITY, hi = -INFINITY;
      for (std::size_t i = static_cast<std::size_t>(j); i < hsh.coefficients.size();
           i += static_cast<std::size_t>(hsh.Terms())) {
        lo = std::min(lo, hsh.coefficients[i]);
        hi = std::max(hi, hsh.coefficients[i]);
      }
      scale[static_cast<std::size_t>(j)] = hi > lo ? hi - lo : 1.0f;
      bias[static_cast<std::size_t>(j)] = lo;
    }
  }
  unsigned char Encode(float v, int j) const {
    const auto k = static_cast<std::size_t>(j);
    return static_cast<unsigned char>(
        std::clamp(std::lround((v - bias[k]) / scale[k] * 255.0f), 0L, 255L));
  }
};

}  // namespace

std::array<double, 9> HshBasis(const Eigen::Vector3d& light) {
  const Eigen::Vector3d l = light.normalized();
  const double x = std::clamp(l.z(), 0.0, 1.0);  // cos(theta)
  const double phi = std::atan2(l.y(), l.x());
  const double s = std::sqrt(std::max(0.0, x - x * x));
  const double c1 = std::cos(phi), s1 = std::sin(phi), c2 = std::cos(2 * phi),
               s2 = std::sin(2 * phi);
  return {1.0 / std::sqrt(2 * kPi),
          std::sqrt(6 / kPi) * c1 * s,
          std::sqrt(3 / (2 * kPi)) * (2 * x - 1),
          std::sqrt(6 / kPi) * s1 * s,
          std::sqrt(30 / kPi) * c2 * (x * x - x),
          std::sqrt(30 / kPi) * c1 * (2 * x - 1) * s,
          std::sqrt(5 / (2 * kPi)) * (6 * x * x - 6 * x + 1),
          std::sqrt(30 / kPi) * s1 * (2 * x - 1) * s,
          std::sqrt(30 / kPi) * s2 * (x * x - x)};
}

HshFitResult FitHshFromFiles(const std::vector<std::filesystem::path>& files,
                             const std::vector<Eigen::Vector3d>& lights, int order, int band_rows,
                             const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (order < kHshMinOrder || order > kHshMaxOrder)
    throw OptionError("the HSH order must be 2 or 3");
  if (band_rows < 1) throw OptionError("band rows must be at least 1");
  const std::string label = files.empty() ? "images" : files[0].parent_path().string();
  const int terms = HshTerms(order);
  // c = (A^T A)^-1 A^T y for every texel and channel: one solve matrix for all.
  const BasisMatrix a = BasisRows(lights, terms);
  CheckLightsForBasis(lights, a, static_cast<std::size_t>(terms), kMaxConditionNumber,
                      "an order-" + std::to_string(order) + " HSH", label);
  const Eigen::MatrixXd solve = (a.transpose() * a).ldlt().solve(a.transpose());
  ImageBands bands(files);
  HshFitResult result;
  Hsh& hsh = result.hsh;
  hsh.order = order;
  hsh.width = bands.width();
  hsh.height = bands.height();
  hsh.coefficients.assign(hsh.NumTexels() * 3 * static_cast<std::size_t>(terms), 0.0f);
  // Each row's residual sum, summed in row order at the end (rows run concurrently).
  std::vector<double> row_residual(static_cast<std::size_t>(hsh.height), 0.0);
  const auto n = static_cast<Eigen::Index>(lights.size());
  bands.ForEach<float>(
      band_rows,
      [&](const std::vector<const float*>& pixels, int y0, int rows) {
        Eigen::VectorXd y(n);
        for (int row = 0; row < rows; ++row) {
          double sum = 0;
          for (int x = 0; x < hsh.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(row) * hsh.width + x;
            const std::size_t t = static_cast<std::size_t>(y0) * hsh.width + i;
            for (int c = 0; c < 3; ++c) {
              for (Eigen::Index k = 0; k < n; ++k)
                y(k) = pixels[static_cast<std::size_t>(k)][i * 3 + static_cast<std::size_t>(c)];
              const Eigen::VectorXd coefficients = solve * y;
              for (int j = 0; j < terms; ++j) hsh.At(t, c)[j] = static_cast<float>(coefficients(j));
              sum += std::sqrt((a * coefficients - y).squaredNorm() / static_cast<double>(n));
            }
          }
          row_residual[static_cast<std::size_t>(y0 + row)] = sum;
        }
      },
      progress, "fit");
  double residual_sum = 0;
  for (const double sum : row_residual) residual_sum += sum;
  result.mean_residual_rms =
      residual_sum / std::max<double>(1.0, 3.0 * static_cast<double>(hsh.NumTexels()));
  result.seconds = SecondsSince(start);
  return result;
}

std::vector<float> RelightHsh(const Hsh& hsh, const Eigen::Vector3d& light) {
  // As texlume evaluates a PTM: below the horizon elevation, the value there fading to 0.
  const EffectiveLight effective =
      Effective(light.normalized(), 1.0, LightResponse{}, Eigen::Vector3d::UnitZ());
  const std::array<double, 9> b = HshBasis(effective.direction);
  std::vector<float> out(hsh.NumTexels() * 3);
  for (std::size_t t = 0; t < hsh.NumTexels(); ++t) {
    for (int c = 0; c < 3; ++c) {
      double v = 0;
      for (int j = 0; j < hsh.Terms(); ++j) v += b[static_cast<std::size_t>(j)] * hsh.At(t, c)[j];
      out[t * 3 + static_cast<std::size_t>(c)] =
          static_cast<float>(std::clamp(v * effective.weight, 0.0, 1.0));
    }
  }
  return out;
}

void WriteRtiFile(const Hsh& hsh, const std::filesystem::path& path) {
  const TermQuantiser q(hsh);
  WriteFileAtomically(
      path,
      [&](std::ostream& out) {
        out << "#HSH1.2\n3\n"
            << hsh.width << " " << hsh.height << " 3\n"
            << hsh.Terms() << " 2 1\n";
        out.write(reinterpret_cast<const char*>(q.scale.data()),
                  static_cast<std::streamsize>(q.scale.size() * 4));
        out.write(reinterpret_cast<const char*>(q.bias.data()),
                  static_cast<std::streamsize>(q.bias.size() * 4));
        std::vector<unsigned char> row(static_cast<std::size_t>(hsh.width) * 3 * hsh.Terms());
        for (int y = hsh.height - 1; y >= 0; --y) {
          std::size_t at = 0;
          for (int x = 0; x < hsh.width; ++x)
            for (int c = 0; c < 3; ++c)
              for (int j = 0; j < hsh.Terms(); ++j)
                row[at++] = q.Encode(hsh.At(static_cast<std::size_t>(y) * hsh.width + x, c)[j], j);
          out.write(reinterpret_cast<const char*>(row.data()),
                    static_cast<std::streamsize>(row.size()));
        }
      },
      true);
}

int WriteHshRelightWeb(const Hsh& hsh, const std::filesystem::path& dir, int jpeg_quality) {
  std::vector<std::vector<float>> planes;  // plane 3j + c: term j of channel c
  for (int j = 0; j < hsh.Terms(); ++j) {
    for (int c = 0; c < 3; ++c) {
      std::vector<float>& p = planes.emplace_back(hsh.NumTexels());
      for (std::size_t t = 0; t < hsh.NumTexels(); ++t) p[t] = hsh.At(t, c)[j];
    }
  }
  WebPlanes web = QuantisePlanes(planes, hsh.width, hsh.height);
  web.type = "hsh";
  return WriteWebPlanes(web, dir, jpeg_quality);
}

}  // namespace texlume::ptm
