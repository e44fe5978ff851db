#pragma once

#include <array>

namespace texlume::ptm {

/// The six monomials of the biquadratic PTM (paper 003 eq. 1) at the light
/// direction (lu, lv) given in the texel's tangent frame:
/// (lu^2, lv^2, lu lv, lu, lv, 1), so L = sum_i a_i * basis_i.
inline std::array<double, 6> PtmBasis(double lu, double lv) {
  return {lu * lu, lv * lv, lu * lv, lu, lv, 1.0};
}

/// Evaluates L(lu, lv) = a0 lu^2 + a1 lv^2 + a2 lu lv + a3 lu + a4 lv + a5
/// (paper 003 eq. 1) for coefficients a0..a5.
inline double EvaluatePtm(const std::array<double, 6>& a, double lu, double lv) {
  return a[0] * lu * lu + a[1] * lv * lv + a[2] * lu * lv + a[3] * lu + a[4] * lv + a[5];
}

}  // namespace texlume::ptm
