#include "ptm/least_squares_bands.h"

#include <omp.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <type_traits>

namespace texlume::ptm {

LeastSquaresBands::LeastSquaresBands(const std::vector<Eigen::Vector3d>& lights)
    : lights_(lights.size()) {
  const Eigen::Matrix<double, Eigen::Dynamic, 6> a = PtmLightMatrix(lights);
  const Eigen::Matrix<double, 6, Eigen::Dynamic> inverse =
      a.completeOrthogonalDecomposition().pseudoInverse();
  pseudo_inverse_.resize(lights.size() * 6);
  for (std::size_t k = 0; k < lights.size(); ++k)
    for (int i = 0; i < 6; ++i)
      pseudo_inverse_[k * 6 + static_cast<std::size_t>(i)] =
          inverse(i, static_cast<Eigen::Index>(k));
  pseudo_inverse_float_.assign(pseudo_inverse_.begin(), pseudo_inverse_.end());
  gram_ = a.transpose() * a;
}

namespace {
template <typename Sum>
const Sum* InverseOf(const std::vector<double>& in_double, const std::vector<float>& in_float) {
  if constexpr (std::is_same_v<Sum, float>) {
    return in_float.data();
  } else {
    return in_double.data();
  }
}
}  // namespace

template <typename Sample, typename Sum>
void LeastSquaresBands::ToPlanes(const std::vector<const Sample*>& pixels, std::size_t width,
                                 std::size_t row, std::size_t x0, int count, Sum* planes) const {
  for (std::size_t k = 0; k < lights_; ++k) {
    for (std::size_t ch = 0; ch < 3; ++ch) {
      const Sample* in = pixels[k] + (row * 3 + ch) * width + x0;
      Sum* out = planes + (k * 3 + ch) * kRun;
      for (int x = 0; x < count; ++x) out[x] = static_cast<Sum>(in[x]);
      std::fill(out + count, out + kRun, Sum{0});
    }
  }
}

double LeastSquaresBands::Quadratic(const double* a) const {
  double q = 0.0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) q += a[i] * gram_(i, j) * a[j];
  return q;
}

template <typename Sum>
void LeastSquaresBands::FitLrgb(const Sum* planes, int x, int count, double unit, std::size_t texel,
                                Ptm& ptm, std::vector<float>& residual) const {
  using L = Lanes<Sum>;
  constexpr int kLanesOf = kLanes<Sum>;
  // Pass 1: 3 x the luminance-weighted colour sum, and the energy.
  L chroma[3] = {L::Zero(), L::Zero(), L::Zero()};
  L energy = L::Zero();
  for (std::size_t k = 0; k < lights_; ++k) {
    const Sum* p = planes + k * 3 * kRun + x;
    const L r = L::Map(p), g = L::Map(p + kRun), b = L::Map(p + 2 * kRun);
    const L sum = r + g + b;
    chroma[0] += sum * r, chroma[1] += sum * g, chroma[2] += sum * b;
    energy += r * r + g * g + b * b;
  }
  // Chromaticity: largest channel 1; the luminance L_k = rgb_k . c / |c|^2.
  L scaled[3];
  Eigen::Vector3d colour[kLanesOf];
  for (int l = 0; l < kLanesOf; ++l) {
    Eigen::Vector3d c(chroma[0][l], chroma[1][l], chroma[2][l]);
    c /= 3.0 * unit * unit;
    c = c.maxCoeff() > 1e-9 ? Eigen::Vector3d(c / c.maxCoeff()) : Eigen::Vector3d::Ones();
    colour[l] = c;
    for (int ch = 0; ch < 3; ++ch) scaled[ch][l] = static_cast<Sum>(c[ch] / c.squaredNorm() / unit);
  }
  // Pass 2: a = A^+ L.
  L a[6] = {L::Zero(), L::Zero(), L::Zero(), L::Zero(), L::Zero(), L::Zero()};
  const Sum* inverse = InverseOf<Sum>(pseudo_inverse_, pseudo_inverse_float_);
  for (std::size_t k = 0; k < lights_; ++k) {
    const Sum* p = planes + k * 3 * kRun + x;
    const L luminance =
        L::Map(p) * scaled[0] + L::Map(p + kRun) * scaled[1] + L::Map(p + 2 * kRun) * scaled[2];
    const Sum* inverse_k = inverse + k * 6;
    for (int i = 0; i < 6; ++i) a[i] += inverse_k[i] * luminance;
  }
  for (int l = 0; l < std::min(kLanesOf, count - x); ++l) {
    const std::size_t t = texel + static_cast<std::size_t>(l);
    double coefficients[6];
    float* out = ptm.Coefficients(t);
    for (int i = 0; i < 6; ++i) out[i] = static_cast<float>(coefficients[i] = a[i][l]);
    for (int ch = 0; ch < 3; ++ch)
      ptm.colour[t * 3 + static_cast<std::size_t>(ch)] = static_cast<float>(colour[l][ch]);
    const double sum_sq = std::max(
        0.0, energy[l] / (unit * unit) - colour[l].squaredNorm() * Quadratic(coefficients));
    residual[t] = ResidualRms(sum_sq, lights_);
  }
}

template <typename Sum>
void LeastSquaresBands::FitRgb(const Sum* planes, int x, int count, double unit, std::size_t texel,
                               Ptm& ptm, std::vector<float>& residual) const {
  using L = Lanes<Sum>;
  constexpr int kLanesOf = kLanes<Sum>;
  const int texels = std::min(kLanesOf, count - x);
  const Sum* inverse = InverseOf<Sum>(pseudo_inverse_, pseudo_inverse_float_);
  double sum_sq[kLanesOf] = {};
  for (int ch = 0; ch < 3; ++ch) {
    L a[6] = {L::Zero(), L::Zero(), L::Zero(), L::Zero(), L::Zero(), L::Zero()};
    L energy = L::Zero();
    for (std::size_t k = 0; k < lights_; ++k) {
      const L v = L::Map(planes + (k * 3 + static_cast<std::size_t>(ch)) * kRun + x);
      const Sum* inverse_k = inverse + k * 6;
      for (int i = 0; i < 6; ++i) a[i] += inverse_k[i] * v;
      energy += v * v;
    }
    for (int l = 0; l < texels; ++l) {
      double coefficients[6];
      float* out = ptm.Coefficients(texel + static_cast<std::size_t>(l), ch);
      for (int i = 0; i < 6; ++i) out[i] = static_cast<float>(coefficients[i] = a[i][l] / unit);
      sum_sq[l] += std::max(0.0, energy[l] / (unit * unit) - Quadratic(coefficients));
    }
  }
  for (int l = 0; l < texels; ++l)
    residual[texel + static_cast<std::size_t>(l)] = ResidualRms(sum_sq[l], lights_);
}

template <typename Sample>
void LeastSquaresBands::Fit(const std::vector<const Sample*>& pixels, double unit, int rows,
                            int width, int first_row, Ptm& ptm,
                            std::vector<float>& residual) const {
  const long runs_per_row = (width + kRun - 1) / kRun;
  const long runs = runs_per_row * rows;
  // On every thread, unless called from ImageBands' tasks (already on every thread).
#pragma omp parallel if (!omp_in_parallel())
  {
    using Sum = SumOf<Sample>;
    std::vector<Sum> planes(lights_ * 3 * kRun);  // per thread, reused for every run
#pragma omp for schedule(dynamic, 8)
    for (long r = 0; r < runs; ++r) {
      const int row = static_cast<int>(r / runs_per_row);
      const int x0 = static_cast<int>(r % runs_per_row) * kRun;
      const int count = std::min(kRun, width - x0);
      const std::size_t texel =
          (static_cast<std::size_t>(first_row) + static_cast<std::size_t>(row)) * width + x0;
      ToPlanes(pixels, static_cast<std::size_t>(width), static_cast<std::size_t>(row),
               static_cast<std::size_t>(x0), count, planes.data());
      for (int x = 0; x < count; x += kLanes<Sum>) {
        if (ptm.format == PtmFormat::kLrgb) {
          FitLrgb(planes.data(), x, count, unit, texel + static_cast<std::size_t>(x), ptm,
                  residual);
        } else {
          FitRgb(planes.data(), x, count, unit, texel + static_cast<std::size_t>(x), ptm, residual);
        }
      }
    }
  }
}

template void LeastSquaresBands::Fit<float>(const std::vector<const float*>&, double, int, int, int,
                                            Ptm&, std::vector<float>&) const;
template void LeastSquaresBands::Fit<std::uint8_t>(const std::vector<const std::uint8_t*>&, double,
                                                   int, int, int, Ptm&, std::vector<float>&) const;

}  // namespace texlume::ptm
