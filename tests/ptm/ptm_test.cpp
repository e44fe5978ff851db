#include "ptm/ptm.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "core/errors.h"
#include "ptm/coefficient_space.h"

namespace texlume::ptm {
namespace {

Eigen::Vector2d RandomDisk(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  while (true) {
    // Drawn one at a time, last first: a call's arguments are evaluated in an
    // unspecified order (GCC right to left, clang left to right).
    const double y = u(rng), x = u(rng);
    const Eigen::Vector2d p(x, y);
    if (p.squaredNorm() < 1) return p;
  }
}

TEST(Ptm, EvaluationFollowsEquations1And2) {
  Ptm ptm;
  ptm.Resize(PtmFormat::kLrgb, 2, 1);
  const float a[6] = {-0.3f, -0.2f, 0.05f, 0.1f, -0.15f, 0.7f};
  std::copy(a, a + 6, ptm.Coefficients(1));
  ptm.colour[3] = 1.0f;
  ptm.colour[4] = 0.5f;
  ptm.colour[5] = 0.25f;
  const double lu = 0.3, lv = -0.4;
  const double l = -0.3 * lu * lu - 0.2 * lv * lv + 0.05 * lu * lv + 0.1 * lu - 0.15 * lv + 0.7;
  const Eigen::Vector3f rgb = ptm.Evaluate(1, lu, lv);
  EXPECT_NEAR(rgb[0], l, 1e-6);
  EXPECT_NEAR(rgb[1], 0.5 * l, 1e-6);
  EXPECT_NEAR(rgb[2], 0.25 * l, 1e-6);
  const auto b = PtmBasis(lu, lv);
  double dot = 0;
  for (int i = 0; i < 6; ++i) dot += a[i] * b[static_cast<std::size_t>(i)];
  EXPECT_NEAR(EvaluatePolynomial(a, lu, lv), dot, 1e-7);
}

TEST(Ptm, CoveredTexelsAreThoseWithAnyCoefficientNotZero) {
  Ptm rgb;
  rgb.Resize(PtmFormat::kRgb, 3, 2);  // zero-filled
  rgb.Coefficients(1, 2)[4] = 0.5f;   // blue's v coefficient of texel 1
  rgb.Coefficients(4, 0)[5] = -1.0f;  // red's constant of texel 4
  EXPECT_EQ(CoveredTexels(rgb), (std::vector<char>{0, 1, 0, 0, 1, 0}));
  Ptm lrgb;
  lrgb.Resize(PtmFormat::kLrgb, 2, 1);
  lrgb.colour[0] = 0.7f;  // colour alone covers nothing
  lrgb.Coefficients(1)[0] = 1e-6f;
  EXPECT_EQ(CoveredTexels(lrgb), (std::vector<char>{0, 1}));
}

TEST(Ptm, NormalIsTheMaximumOfTheBiquadratic) {
  // L = 1 - |l - m|^2 peaks at m = (0.3, -0.2): a0 = a1 = -1, a3 = 2 mx, a4 = 2 my.
  const float a[6] = {-1, -1, 0, 0.6f, -0.4f, 1 - 0.13f};
  const Eigen::Vector3d n = PtmNormal(a);
  EXPECT_NEAR(n.x(), 0.3, 1e-6);
  EXPECT_NEAR(n.y(), -0.2, 1e-6);
  EXPECT_NEAR(n.norm(), 1.0, 1e-9);
  const float flat[6] = {0, 0, 0, 0, 0, 0.5f};
  EXPECT_TRUE(PtmNormal(flat).isApprox(Eigen::Vector3d::UnitZ()));
}

TEST(Ptm, DiffuseGainKeepsTheValueAtTheNormal) {
  Ptm ptm;
  ptm.Resize(PtmFormat::kRgb, 1, 1);
  const float a[6] = {-0.5f, -0.4f, 0.1f, 0.2f, -0.1f, 0.6f};
  for (int c = 0; c < 3; ++c) std::copy(a, a + 6, ptm.Coefficients(0, c));
  const Eigen::Vector3d n = PtmNormal(a);
  EnhancementOptions gain;
  gain.diffuse_gain = 3.0;
  const auto plain = Relight(ptm, n, {});
  const auto enhanced = Relight(ptm, n, gain);
  EXPECT_NEAR(plain[0], enhanced[0], 1e-5);
  // Away from the normal the enhanced one falls off faster.
  const Eigen::Vector3d oblique = Eigen::Vector3d(0.6, 0.0, 0.8);
  EXPECT_LT(Relight(ptm, oblique, gain)[0], Relight(ptm, oblique, {})[0]);
}

TEST(CoefficientSpace, OrthonormalDistanceEqualsFunctionDistanceOverTheHemisphere) {
  const auto& basis = OrthonormalBasis::Hemisphere();
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::Matrix<double, 6, 1> a, b;
    for (int i = 0; i < 6; ++i) a[i] = g(rng), b[i] = g(rng);
    // Monte Carlo over uniformly distributed directions (solid angle 2 pi).
    std::uniform_real_distribution<double> u(0, 1);
    double sum = 0;
    const int n = 400000;
    for (int k = 0; k < n; ++k) {
      const double z = u(rng), phi = 2 * M_PI * u(rng), s = std::sqrt(1 - z * z);
      const auto m = PtmBasis(s * std::cos(phi), s * std::sin(phi));
      double d = 0;
      for (int i = 0; i < 6; ++i) d += (a[i] - b[i]) * m[static_cast<std::size_t>(i)];
      sum += d * d;
    }
    const double function_distance2 = 2 * M_PI * sum / n;
    const double coefficient_distance2 = (basis.ToOrthonormal() * (a - b)).squaredNorm();
    EXPECT_NEAR(coefficient_distance2, function_distance2, 0.01 * function_distance2);
  }
  EXPECT_TRUE((basis.FromOrthonormal() * basis.ToOrthonormal()).isIdentity(1e-12));
  EXPECT_NEAR(basis.Gram()(5, 5), 2 * M_PI, 1e-9);      // integral of 1
  EXPECT_NEAR(basis.Gram()(0, 5), 2 * M_PI / 3, 1e-9);  // integral of lu^2
}

TEST(CoefficientSpace, FrameRotationMatchesDirectEvaluation) {
  std::mt19937 rng(9);
  for (double angle : {0.0, 0.3, 1.7, -2.4, M_PI}) {
    const Eigen::Matrix<double, 6, 6> m = FrameRotation(angle);
    Eigen::Matrix<double, 6, 1> a;
    a << -0.4, 0.2, 0.3, -0.1, 0.25, 0.6;
    const Eigen::Matrix<double, 6, 1> rotated = m * a;
    float af[6], rf[6];
    for (int i = 0; i < 6; ++i)
      af[i] = static_cast<float>(a[i]), rf[i] = static_cast<float>(rotated[i]);
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector2d new_frame = RandomDisk(rng);
      const Eigen::Vector2d old_frame = Eigen::Rotation2Dd(angle) * new_frame;
      EXPECT_NEAR(EvaluatePolynomial(rf, new_frame.x(), new_frame.y()),
                  EvaluatePolynomial(af, old_frame.x(), old_frame.y()), 1e-6);
    }
    // Rotations compose and invert.
    EXPECT_TRUE((FrameRotation(-angle) * m).isIdentity(1e-12));
  }
  EXPECT_TRUE((FrameRotation(0.4) * FrameRotation(0.5)).isApprox(FrameRotation(0.9), 1e-12));
}

TEST(EnhancementOptions, OutOfRangeSettingsAreRefused) {
  EnhancementOptions o;
  EXPECT_NO_THROW(o.Check());
  o.diffuse_gain = 0.5;
  EXPECT_THROW(o.Check(), OptionError);
  o.diffuse_gain = 2.0;
  o.specular = 11.0;
  EXPECT_THROW(o.Check(), OptionError);
  o.specular = 1.0;
  o.specular_exponent = 0.0;
  EXPECT_THROW(o.Check(), OptionError);
  Ptm ptm;
  ptm.Resize(PtmFormat::kLrgb, 2, 2);
  EXPECT_THROW(Relight(ptm, Eigen::Vector3d::UnitZ(), o), OptionError);
}

}  // namespace
}  // namespace texlume::ptm
