#pragma once

#include <ceres/sized_cost_function.h>

#include <algorithm>
#include <array>

namespace texlume::ptm {

/// Ceres cost of one sample of a texel's polynomial, r = b(l) . a - I (paper 003 eq. 1),
/// for the robust fit's Cauchy refinement (ptm/fit.cpp). The polynomial is linear in its
/// coefficients a, so the Jacobian dr/da is b(l) itself: written out, not differentiated
/// by Ceres' automatic differentiation (the same values, and fit.cpp compiles without
/// Ceres' dual numbers). Exposed for the gradient check in the tests.
class PtmSampleCost final : public ceres::SizedCostFunction<1, 6> {
 public:
  PtmSampleCost(const std::array<double, 6>& basis, double observed)
      : basis_(basis), observed_(observed) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* a = parameters[0];
    double sum = -observed_;
    for (std::size_t i = 0; i < basis_.size(); ++i) sum += basis_[i] * a[i];
    residuals[0] = sum;
    if (jacobians != nullptr && jacobians[0] != nullptr)
      std::copy(basis_.begin(), basis_.end(), jacobians[0]);
    return true;
  }

 private:
  std::array<double, 6> basis_;
  double observed_;
};

}  // namespace texlume::ptm
