#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ptm/ptm.h"

namespace texlume::ptm {

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
  /// `rows` x `width` interleaved RGB, `unit` per 1 (255 for 8-bit, 1 for floats).
  template <typename Sample>
  void Fit(const std::vector<const Sample*>& pixels, double unit, int rows, int width,
           int first_row, Ptm& ptm, std::vector<float>& residual) const;

 private:
  static constexpr int kRun = 32;   ///< texels converted to planes at once
  static constexpr int kLanes = 4;  ///< texels whose sums stay in registers
  using Lanes = Eigen::Array<double, kLanes, 1>;

  /// The planes of a run: image k's channel ch at planes[(k * 3 + ch) * kRun + x],
  /// zero past `count` texels.
  template <typename Sample>
  void ToPlanes(const std::vector<const Sample*>& pixels, std::size_t first, int count,
                double* planes) const;
  /// Fits the kLanes texels from `x` of a run's planes; writes those before `count`.
  void FitLrgb(const double* planes, int x, int count, double unit, std::size_t texel, Ptm& ptm,
               std::vector<float>& residual) const;
  void FitRgb(const double* planes, int x, int count, double unit, std::size_t texel, Ptm& ptm,
              std::vector<float>& residual) const;
  double Quadratic(const double* a) const;  ///< a^T (A^T A) a

  std::size_t lights_ = 0;
  std::vector<double> pseudo_inverse_;  ///< A^+ by light: pseudo_inverse_[k * 6 + i]
  Eigen::Matrix<double, 6, 6> gram_;    ///< A^T A
};

}  // namespace texlume::ptm
