#include "ptm/fit.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/errors.h"
#include "datasets_synthetic/scene.h"
#include "ptm/ptm_sample_cost.h"
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
  const PtmSampleCost cost(basis, 0.42);
  double a[6] = {0.1, -0.2, 0.3, 0.05, -0.4, 0.5};
  const double* parameters[] = {a};
  // The known answer: r = b . a - I, and dr/da = b.
  double residual = 0.0, jacobian[6] = {};
  double* jacobians[] = {jacobian};
  ASSERT_TRUE(cost.Evaluate(parameters, &residual, jacobians));
  double expected = -0.42;
  for (int i = 0; i < 6; ++i) expected += basis[static_cast<std::size_t>(i)] * a[i];
  EXPECT_NEAR(residual, expected, 1e-15);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(jacobian[i], basis[static_cast<std::size_t>(i)]);
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

// The images of `k` with noise, rounded to 8 bits, in memory and as 8-bit and
// 16-bit PNGs (the same values: 16-bit = 8-bit x 257).
struct QuantisedCapture {
  std::vector<ImageRgb> images;
  std::vector<std::filesystem::path> png8, png16;
};

QuantisedCapture WriteQuantised(const KnownPtm& k, const std::filesystem::path& dir) {
  QuantisedCapture q;
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  for (std::size_t n = 0; n < k.images.size(); ++n) {
    const ImageRgb& image = k.images[n];
    cv::Mat bgr8(image.height, image.width, CV_8UC3);
    ImageRgb quantised = image;
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
      const float byte = std::round(std::clamp(image.pixels[i] + noise(rng), 0.0f, 1.0f) * 255);
      quantised.pixels[i] = byte / 255.0f;
      bgr8.data[i / 3 * 3 + 2 - i % 3] = static_cast<std::uint8_t>(byte);
    }
    cv::Mat bgr16;
    bgr8.convertTo(bgr16, CV_16UC3, 257.0);
    q.png8.push_back(dir / ("e" + std::to_string(n) + ".png"));
    q.png16.push_back(dir / ("s" + std::to_string(n) + ".png"));
    cv::imwrite(q.png8.back().string(), bgr8);
    cv::imwrite(q.png16.back().string(), bgr16);
    q.images.push_back(std::move(quantised));
  }
  return q;
}

// The residual RMS of texel t by its definition: over lights and channels.
double ResidualByDefinition(const FitResult& r, const std::vector<ImageRgb>& images,
                            const std::vector<Eigen::Vector3d>& lights, std::size_t t) {
  double sum_sq = 0.0;
  for (std::size_t k = 0; k < images.size(); ++k) {
    const Eigen::Vector3f v = r.ptm.Evaluate(t, lights[k].x(), lights[k].y());
    for (int c = 0; c < 3; ++c)
      sum_sq += std::pow(v[c] - images[k].pixels[t * 3 + static_cast<std::size_t>(c)], 2);
  }
  return std::sqrt(sum_sq / (3.0 * static_cast<double>(images.size())));
}

TEST(Fit, FilesOfEveryDepthAndBandFitAsTheImagesInMemory) {
  testing::TempDir tmp;
  const KnownPtm k = MakeKnown(37, 13, 14, 6);  // bands of 5 rows: the last one short
  const QuantisedCapture q = WriteQuantised(k, tmp.path());
  for (const PtmFormat format : {PtmFormat::kLrgb, PtmFormat::kRgb}) {
    for (const bool robust : {false, true}) {
      FitOptions options;
      options.format = format;
      options.robust = robust;
      options.band_rows = 5;
      const FitResult memory = FitPtm(q.images, k.lights, options);
      for (const auto* files : {&q.png8, &q.png16}) {
        const FitResult streamed = FitPtmFromFiles(*files, k.lights, options);
        SCOPED_TRACE(std::string(format == PtmFormat::kLrgb ? "LRGB" : "RGB") +
                     (robust ? ", robust, " : ", ") + (files == &q.png8 ? "8-bit" : "16-bit"));
        for (std::size_t i = 0; i < memory.ptm.coefficients.size(); ++i)
          ASSERT_NEAR(streamed.ptm.coefficients[i], memory.ptm.coefficients[i], 1e-5);
        for (std::size_t i = 0; i < memory.ptm.colour.size(); ++i)
          ASSERT_NEAR(streamed.ptm.colour[i], memory.ptm.colour[i], 1e-5);
        for (std::size_t t = 0; t < memory.residual_rms.size(); ++t)
          ASSERT_NEAR(streamed.residual_rms[t], memory.residual_rms[t], 1e-5);
      }
      if (robust) continue;
      // The one-pass residual (energy minus a^T A^T A a) is the residual's definition.
      for (std::size_t t = 0; t < memory.residual_rms.size(); t += 7)
        ASSERT_NEAR(memory.residual_rms[t], ResidualByDefinition(memory, q.images, k.lights, t),
                    1e-5);
      EXPECT_GT(memory.mean_residual_rms, 0.02);  // the noise is there to be measured
    }
  }
}

TEST(FitBadInput, ATruncatedImageAmongManyIsNamedWhicheverThreadDecodesIt) {
  testing::TempDir tmp;
  const KnownPtm k = MakeKnown(40, 64, 9, 7);
  const QuantisedCapture q = WriteQuantised(k, tmp.path());
  for (const std::size_t broken : {std::size_t{0}, std::size_t{5}}) {
    const auto& file = q.png8[broken];
    const auto size = std::filesystem::file_size(file);
    const auto copy = tmp / "whole.png";
    std::filesystem::copy_file(file, copy, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(file, size / 3);
    FitOptions options;
    options.band_rows = 8;
    const std::string message =
        testing::InputErrorMessage([&] { FitPtmFromFiles(q.png8, k.lights, options); });
    EXPECT_NE(message.find(file.filename().string()), std::string::npos) << message;
    std::filesystem::rename(copy, file);
  }
  EXPECT_NO_THROW(FitPtmFromFiles(q.png8, k.lights, FitOptions{}));
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
