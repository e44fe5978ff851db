#include "ptm/fit.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "datasets_synthetic/scene.h"
#include "sfm/lights.h"
#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

// Images generated from known polynomials: a known answer for the fit.
struct KnownPtm {
  std::vector<ImageRgb> images;
  std::vector<Eigen::Vector3d> lights;
  Ptm truth;
};

KnownPtm MakeKnown(int width, int height, int num_lights, std::uint32_t seed) {
  KnownPtm k;
  k.lights = datasets::DomeLights(num_lights, 15, 80, 0.0);
  k.truth.Resize(PtmFormat::kRgb, width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.2f, 0.2f);
  for (std::size_t t = 0; t < k.truth.NumTexels(); ++t) {
    for (int c = 0; c < 3; ++c) {
      float* a = k.truth.Coefficients(t, c);
      for (int i = 0; i < 6; ++i) a[i] = u(rng);
      a[5] += 0.5f;
    }
  }
  for (const auto& l : k.lights) {
    ImageRgb image{width, height, std::vector<float>(k.truth.NumTexels() * 3)};
    for (std::size_t t = 0; t < k.truth.NumTexels(); ++t) {
      const Eigen::Vector3f v = k.truth.Evaluate(t, l.x(), l.y());
      for (int c = 0; c < 3; ++c) image.pixels[t * 3 + static_cast<std::size_t>(c)] = v[c];
    }
    k.images.push_back(std::move(image));
  }
  return k;
}

TEST(Fit, LeastSquaresRecoversKnownPolynomialsExactly) {
  const KnownPtm k = MakeKnown(16, 12, 20, 1);
  FitOptions options;
  options.format = PtmFormat::kRgb;
  const FitResult r = FitPtm(k.images, k.lights, options);
  for (std::size_t i = 0; i < k.truth.coefficients.size(); ++i) {
    ASSERT_NEAR(r.ptm.coefficients[i], k.truth.coefficients[i], 1e-4);
  }
  EXPECT_LT(r.mean_residual_rms, 1e-5);
}

TEST(Fit, LrgbReproducesGreyscaleShadingAndColour) {
  KnownPtm k = MakeKnown(8, 8, 12, 2);
  // Make the truth LRGB-like: one luminance polynomial times a colour.
  for (auto& image : k.images) {
    for (std::size_t t = 0; t < image.pixels.size() / 3; ++t) {
      const float l = image.pixels[t * 3];
      image.pixels[t * 3 + 1] = 0.5f * l;
      image.pixels[t * 3 + 2] = 0.25f * l;
    }
  }
  const FitResult r = FitPtm(k.images, k.lights, FitOptions{});
  EXPECT_LT(r.mean_residual_rms, 1e-5);
  EXPECT_NEAR(r.ptm.colour[1], 0.5f, 1e-5);
  EXPECT_NEAR(r.ptm.colour[2], 0.25f, 1e-5);
}

TEST(Fit, RobustFitIgnoresShadowsAndHighlightsThatPullLeastSquares) {
  KnownPtm k = MakeKnown(10, 10, 40, 3);
  // Corrupt a quarter of the samples: black shadows and saturated highlights.
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> pick(0, 3);
  for (auto& image : k.images) {
    for (std::size_t t = 0; t < image.pixels.size() / 3; ++t) {
      const int p = pick(rng);
      if (p == 0) image.pixels[t * 3] = image.pixels[t * 3 + 1] = image.pixels[t * 3 + 2] = 0.0f;
      if (p == 1 && t % 2)
        image.pixels[t * 3] = image.pixels[t * 3 + 1] = image.pixels[t * 3 + 2] = 1.0f;
    }
  }
  FitOptions options;
  options.format = PtmFormat::kRgb;
  const FitResult ls = FitPtm(k.images, k.lights, options);
  options.robust = true;
  const FitResult robust = FitPtm(k.images, k.lights, options);
  double err_ls = 0, err_robust = 0;
  for (std::size_t i = 0; i < k.truth.coefficients.size(); ++i) {
    err_ls += std::pow(ls.ptm.coefficients[i] - k.truth.coefficients[i], 2);
    err_robust += std::pow(robust.ptm.coefficients[i] - k.truth.coefficients[i], 2);
  }
  EXPECT_LT(err_robust, 0.05 * err_ls);
}

TEST(Fit, CeresCostFunctionPassesTheGradientCheck) {
  const auto basis = PtmBasis(0.3, -0.5);
  ceres::AutoDiffCostFunction<PtmSampleResidual, 1, 6> cost(new PtmSampleResidual(basis, 0.42));
  double a[6] = {0.1, -0.2, 0.3, 0.05, -0.4, 0.5};
  const double* parameters[] = {a};
  ceres::NumericDiffOptions numeric;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&cost, no_manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters, 1e-9, &results)) << results.error_log;
}

TEST(Fit, PerTexelLightsMatchSharedLightsWhenTheyAgree) {
  const KnownPtm k = MakeKnown(6, 5, 15, 5);
  FitOptions options;
  options.format = PtmFormat::kRgb;
  const FitResult shared = FitPtm(k.images, k.lights, options);
  const FitResult per_texel = FitPtmPerTexelLights(
      k.images, [&](int image, int, int) { return k.lights[static_cast<std::size_t>(image)]; },
      options);
  for (std::size_t i = 0; i < shared.ptm.coefficients.size(); ++i) {
    ASSERT_NEAR(shared.ptm.coefficients[i], per_texel.ptm.coefficients[i], 1e-4);
  }
}

TEST(FitBadInput, FewDegenerateAndLowLightsAreRefused) {
  FitOptions options;
  auto message = [&](const std::vector<Eigen::Vector3d>& lights) {
    return testing::InputErrorMessage([&] { CheckLightSet(lights, options, "lights.lp"); });
  };
  EXPECT_NE(message(datasets::DomeLights(5, 20, 70, 0)).find("at least 6"), std::string::npos);
  // Eight lights on one great circle (lv = 0): lv terms are unconstrained.
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 8; ++i) {
    const double t = -0.9 + 1.8 * i / 7;
    line.emplace_back(t, 0.0, std::sqrt(1 - t * t));
  }
  EXPECT_NE(message(line).find("degenerate"), std::string::npos);
  auto low = datasets::DomeLights(10, 20, 70, 0);
  low[3] = Eigen::Vector3d(1, 0, -0.1).normalized();
  EXPECT_NE(message(low).find("horizon"), std::string::npos);
  EXPECT_EQ(message(datasets::DomeLights(10, 20, 70, 0)), "");
}

TEST(RtiCapture, NamesOfAnotherCaseFindTheOneFileThatMatchesWithAWarning) {
  testing::TempDir tmp;
  testing::WriteText(tmp / "rti_000.png", "");
  testing::WriteText(tmp / "rti_001.png", "");
  testing::WriteText(tmp / "lights.lp", "2\nRTI_000.PNG 0 0 1\nrti_001.png 0.6 0 0.8\n");
  const RtiCapture capture = ReadRtiCapture(tmp / "lights.lp", tmp.path());
  ASSERT_EQ(capture.files.size(), 2u);
  EXPECT_EQ(capture.files[0], tmp / "rti_000.png");
  EXPECT_EQ(capture.files[1], tmp / "rti_001.png");
  ASSERT_EQ(capture.warnings.size(), 1u);  // the exact name takes no warning
  EXPECT_NE(capture.warnings[0].find("'RTI_000.PNG'; using rti_000.png"), std::string::npos)
      << capture.warnings[0];
}

TEST(RtiCaptureBadInput, AmbiguousAndMissingNamesAreRefused) {
  testing::TempDir tmp;
  testing::WriteText(tmp / "rti_000.png", "");
  testing::WriteText(tmp / "Rti_000.png", "");
  testing::WriteText(tmp / "lights.lp", "1\nRTI_000.PNG 0 0 1\n");
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadRtiCapture(tmp / "lights.lp", tmp.path());
            }).find("several files match it ignoring case"),
            std::string::npos);
  testing::WriteText(tmp / "lights.lp", "1\nrti_009.png 0 0 1\n");
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadRtiCapture(tmp / "lights.lp", tmp.path());
            }).find("does not exist"),
            std::string::npos);
}

}  // namespace
}  // namespace texlume::ptm
