#pragma once

#include <Eigen/Core>

namespace texlume::ptm {

/// The orthonormal coefficient basis of paper 003 §2.3. With G the Gram matrix of
/// the six monomials of eq. 1 over the hemisphere of light directions (uniform
/// solid-angle measure), G = L L^T (Cholesky), the map a -> L^T a makes the
/// Euclidean distance of coefficient vectors equal the L2 distance of the
/// functions over the hemisphere: |L^T (a - b)|^2 = integral (f_a - f_b)^2 dw.
/// Distances and blends of PTM texels go through it.
class OrthonormalBasis {
 public:
  /// The basis for the hemisphere (computed once, by quadrature).
  static const OrthonormalBasis& Hemisphere();

  /// The Gram matrix G_ij = integral b_i b_j dw over the hemisphere.
  const Eigen::Matrix<double, 6, 6>& Gram() const { return gram_; }
  /// a -> orthonormal coordinates (L^T).
  const Eigen::Matrix<double, 6, 6>& ToOrthonormal() const { return to_orthonormal_; }
  /// orthonormal coordinates -> a (L^-T).
  const Eigen::Matrix<double, 6, 6>& FromOrthonormal() const { return from_orthonormal_; }

 private:
  OrthonormalBasis();
  Eigen::Matrix<double, 6, 6> gram_, to_orthonormal_, from_orthonormal_;
};

/// The 6x6 map of coefficients when the tangent frame turns by `angle_rad`
/// (counter-clockwise about the normal): if the new x axis is
/// cos(angle) x + sin(angle) y, a light with new-frame components (lu', lv') has
/// old-frame components R(angle) (lu', lv'), and a' = M a satisfies
/// L'(lu', lv') = L(lu, lv) for every light.
Eigen::Matrix<double, 6, 6> FrameRotation(double angle_rad);

/// FrameRotation in the orthonormal coordinates of OrthonormalBasis::Hemisphere
/// (L^T M L^-T): what moves orthonormal coefficient vectors between frames.
Eigen::Matrix<double, 6, 6> OrthonormalFrameRotation(double angle_rad);

}  // namespace texlume::ptm
