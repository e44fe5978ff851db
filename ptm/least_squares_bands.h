#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "ptm/ptm.h"

namespace texlume::ptm {

/// A texel's residual RMS over its `images` samples' three channels, from the sum
/// of their squared differences.
inline float ResidualRms(double sum_sq, std::size_t images) {
  return static_cast<float>(std::sqrt(sum_sq / (3.0 * static_cast<double>(images))));
}

/// The closed-form least-squares PTM fit of bands of images lit from the same
/// directions (Malzbender et al. 2001: a = A^+ L per texel, A the light matrix),
/// with no per-texel matrix work and no per-sample conversion beyond one to double:
/// - an LRGB texel first sums its luminance-weighted colour c = sum_k mean(rgb_k)
///   rgb_k and its energy sum_k |rgb_k|^2, then a = A^+ L with L_k = rgb_k . c / |c|^2;
/// - an RGB texel's channel has a = A^+ v over the channel's values v_k;
/// - the residual is the energy minus |c|^2 a^T (A^T A) a (LRGB) or a^T (A^T A) a per
///   channel (RGB): no second pass over the samples.
/// Texels are fitted kLanes at a time with their sums held in registers, over a run
/// of the band converted once to planes.
class LeastSquaresBands {
 public:
  /// `lights`: unit directions (tangent frame, z > 0), checked by the caller.
  explicit LeastSquaresBands(const std::vector<Eigen::Vector3d>& lights);

  /// Fits texels [first_row * width, (first_row + rows) * width) of `ptm` (its
  /// format chosen) and their residual RMS in [0, 1] units. pixels[k]: image k's
  /// `rows` x `width` band, each row as its R, then G, then B values
  /// (BandLayout::kRowPlanar), `unit`
  /// per 1 (255 for 8-bit, 1 for floats).
  template <typename Sample>
  void Fit(const std::vector<const Sample*>& pixels, double unit, int rows, int width,
           int first_row, Ptm& ptm, std::vector<float>& residual) const;

 private:
  static constexpr int kRun = 32;  ///< texels converted to planes at once
  /// Texels whose sums stay in registers: two SSE registers of Sum.
  template <typename Sum>
  static constexpr int kLanes = static_cast<int>(32 / sizeof(Sum));
  template <typename Sum>
  using Lanes = Eigen::Array<Sum, kLanes<Sum>, 1>;
  /// The sums of 8-bit samples are floats: exact for the colour and energy sums up
  /// to 2^24 (85 images; beyond, 6e-8 relative), and 1e-7 relative for the
  /// coefficients, far below the samples' own step of 1/255. Float samples are
  /// summed in double.
  template <typename Sample>
  using SumOf = std::conditional_t<std::is_same_v<Sample, std::uint8_t>, float, double>;

  /// The planes of the run of `count` texels from x0 in the band's row `row`: image
  /// k's channel ch at planes[(k * 3 + ch) * kRun + x], zero past `count` texels.
  template <typename Sample, typename Sum>
  void ToPlanes(const std::vector<const Sample*>& pixels, std::size_t width, std::size_t row,
                std::size_t x0, int count, Sum* planes) const;
  /// Fits the kLanes texels from `x` of a run's planes; writes those before `count`.
  template <typename Sum>
  void FitLrgb(const Sum* planes, int x, int count, double unit, std::size_t texel, Ptm& ptm,
               std::vector<float>& residual) const;
  template <typename Sum>
  void FitRgb(const Sum* planes, int x, int count, double unit, std::size_t texel, Ptm& ptm,
              std::vector<float>& residual) const;
  double Quadratic(const double* a) const;  ///< a^T (A^T A) a

  std::size_t lights_ = 0;
  std::vector<double> pseudo_inverse_;       ///< A^+ by light: pseudo_inverse_[k * 6 + i]
  std::vector<float> pseudo_inverse_float_;  ///< the same in floats
  Eigen::Matrix<double, 6, 6> gram_;         ///< A^T A
};

}  // namespace texlume::ptm
