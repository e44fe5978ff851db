#include "ptm/coefficient_space.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <numbers>

#include "ptm/ptm.h"

namespace texlume::ptm {

OrthonormalBasis::OrthonormalBasis() {
  // Quadrature over the hemisphere in (theta, phi): Gauss-Legendre in cos(theta)
  // (exact for the polynomial integrands), uniform in phi.
  constexpr int kRings = 24, kSegments = 64;
  // Gauss-Legendre nodes on [0, 1] by Newton iteration on P_n.
  double nodes[kRings], weights[kRings];
  for (int i = 0; i < kRings; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (kRings + 0.5));
    double dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= kRings; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = kRings * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-15) break;
    }
    nodes[i] = 0.5 * (x + 1);                    // mu = cos(theta) in [0, 1]
    weights[i] = 1.0 / ((1 - x * x) * dp * dp);  // 2 / ((1-x^2) P'^2), halved for [0, 1]
  }
  gram_.setZero();
  for (int i = 0; i < kRings; ++i) {
    const double mu = nodes[i], sin_theta = std::sqrt(1 - mu * mu);
    for (int j = 0; j < kSegments; ++j) {
      const double phi = 2 * std::numbers::pi * (j + 0.5) / kSegments;
      const auto b = PtmBasis(sin_theta * std::cos(phi), sin_theta * std::sin(phi));
      const double w = weights[i] * 2 * std::numbers::pi / kSegments;  // d(mu) d(phi)
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
          gram_(r, c) += w * b[static_cast<std::size_t>(r)] * b[static_cast<std::size_t>(c)];
    }
  }
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(gram_);
  const Eigen::Matrix<double, 6, 6> l = llt.matrixL();
  to_orthonormal_ = l.transpose();
  from_orthonormal_ = to_orthonormal_.inverse();
}

const OrthonormalBasis& OrthonormalBasis::Hemisphere() {
  static const OrthonormalBasis basis;
  return basis;
}

Eigen::Matrix<double, 6, 6> FrameRotation(double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  // lu = c u - s v, lv = s u + c v in terms of the new components (u, v).
  // Expand each old monomial in the new monomials (u^2, v^2, uv, u, v, 1):
  Eigen::Matrix<double, 6, 6> expand = Eigen::Matrix<double, 6, 6>::Zero();
  expand.col(0) << c * c, s * s, -2 * c * s, 0, 0, 0;      // lu^2
  expand.col(1) << s * s, c * c, 2 * c * s, 0, 0, 0;       // lv^2
  expand.col(2) << c * s, -c * s, c * c - s * s, 0, 0, 0;  // lu lv
  expand.col(3) << 0, 0, 0, c, -s, 0;                      // lu
  expand.col(4) << 0, 0, 0, s, c, 0;                       // lv
  expand.col(5) << 0, 0, 0, 0, 0, 1;                       // 1
  return expand;
}

Eigen::Matrix<double, 6, 6> OrthonormalFrameRotation(double angle_rad) {
  const OrthonormalBasis& basis = OrthonormalBasis::Hemisphere();
  return basis.ToOrthonormal() * FrameRotation(angle_rad) * basis.FromOrthonormal();
}

}  // namespace texlume::ptm
