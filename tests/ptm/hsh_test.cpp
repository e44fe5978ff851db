// Hemispherical harmonics: the basis is orthonormal over the hemisphere, a fit recovers
// known coefficients, and the .rti and web files hold what was fitted.
#include "ptm/hsh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/errors.h"
#include "core/file_util.h"
#include "datasets_synthetic/scene.h"
#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

TEST(HshBasis, IsOrthonormalOverTheUpperHemisphere) {
  // Midpoint rule in (cos theta, phi): d omega = d(cos theta) d phi.
  constexpr int kSteps = 400;
  double gram[9][9] = {};
  for (int i = 0; i < kSteps; ++i) {
    const double z = (i + 0.5) / kSteps;
    for (int k = 0; k < kSteps; ++k) {
      const double phi = 2 * M_PI * (k + 0.5) / kSteps;
      const double r = std::sqrt(1 - z * z);
      const std::array<double, 9> b = HshBasis({r * std::cos(phi), r * std::sin(phi), z});
      for (int p = 0; p < 9; ++p)
        for (int q = 0; q < 9; ++q)
          gram[p][q] += b[p] * b[q] * (1.0 / kSteps) * (2 * M_PI / kSteps);
    }
  }
  for (int p = 0; p < 9; ++p)
    for (int q = 0; q < 9; ++q) EXPECT_NEAR(gram[p][q], p == q ? 1.0 : 0.0, 2e-3) << p << " " << q;
}

// Images of a known order-3 HSH at dome lights, as 16-bit PNGs.
struct KnownHsh {
  Hsh truth;
  std::vector<std::filesystem::path> files;
  std::vector<Eigen::Vector3d> lights;
};

KnownHsh WriteKnownCapture(const std::filesystem::path& dir, int order) {
  KnownHsh k;
  k.truth.order = order;
  k.truth.width = 5;
  k.truth.height = 4;
  k.truth.coefficients.resize(k.truth.NumTexels() * 3 * k.truth.Terms());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.04f, 0.04f);
  for (std::size_t t = 0; t < k.truth.NumTexels(); ++t)
    for (int c = 0; c < 3; ++c) {
      float* a = k.truth.At(t, c);
      for (int j = 0; j < k.truth.Terms(); ++j) a[j] = u(rng);
      a[0] += 1.0f;  // about 0.4 at every light
    }
  k.lights = datasets::DomeLights(24, 20, 80, 0.0);
  for (std::size_t n = 0; n < k.lights.size(); ++n) {
    const std::array<double, 9> b = HshBasis(k.lights[n]);
    cv::Mat image(k.truth.height, k.truth.width, CV_16UC3);
    for (int y = 0; y < k.truth.height; ++y)
      for (int x = 0; x < k.truth.width; ++x)
        for (int c = 0; c < 3; ++c) {
          double v = 0;
          for (int j = 0; j < k.truth.Terms(); ++j)
            v += b[static_cast<std::size_t>(j)] *
                 k.truth.At(static_cast<std::size_t>(y) * k.truth.width + x, c)[j];
          image.at<cv::Vec3w>(y, x)[2 - c] = static_cast<std::uint16_t>(std::lround(v * 65535.0));
        }
    k.files.push_back(dir / ("rti_" + std::to_string(n) + ".png"));
    cv::imwrite(k.files.back().string(), image);
  }
  return k;
}

TEST(HshFit, RecoversKnownCoefficientsAndRelightsTheImages) {
  for (const int order : {2, 3}) {
    testing::TempDir tmp;
    const KnownHsh k = WriteKnownCapture(tmp.path(), order);
    const HshFitResult fit = FitHshFromFiles(k.files, k.lights, order, 3);
    ASSERT_EQ(fit.hsh.Terms(), order * order);
    for (std::size_t i = 0; i < k.truth.coefficients.size(); ++i)
      EXPECT_NEAR(fit.hsh.coefficients[i], k.truth.coefficients[i], 2e-4)
          << "order " << order << ", " << i;
    EXPECT_LT(fit.mean_residual_rms, 1e-5);
    const std::vector<float> relit = RelightHsh(fit.hsh, k.lights[5]);
    const cv::Mat image = cv::imread(k.files[5].string(), cv::IMREAD_UNCHANGED);
    EXPECT_NEAR(relit[(1 * 5 + 2) * 3 + 0], image.at<cv::Vec3w>(1, 2)[2] / 65535.0, 1e-4);
  }
}

TEST(HshFit, TooFewOrDegenerateLightsAndBadOrdersAreRefused) {
  testing::TempDir tmp;
  const KnownHsh k = WriteKnownCapture(tmp.path(), 3);
  const std::vector<std::filesystem::path> few(k.files.begin(), k.files.begin() + 8);
  const std::vector<Eigen::Vector3d> few_lights(k.lights.begin(), k.lights.begin() + 8);
  EXPECT_NE(testing::InputErrorMessage([&] {
              FitHshFromFiles(few, few_lights, 3, 8);
            }).find("8 usable lights; an order-3 HSH needs at least 9"),
            std::string::npos);
  std::vector<Eigen::Vector3d> ring(k.lights.size(), Eigen::Vector3d::Zero());
  for (std::size_t n = 0; n < ring.size(); ++n) {  // one elevation: theta-only terms are confounded
    const double phi = 2 * M_PI * n / ring.size();
    ring[n] = Eigen::Vector3d(0.8 * std::cos(phi), 0.8 * std::sin(phi), 0.6);
  }
  EXPECT_NE(
      testing::InputErrorMessage([&] { FitHshFromFiles(k.files, ring, 3, 8); }).find("degenerate"),
      std::string::npos);
  EXPECT_THROW(FitHshFromFiles(k.files, k.lights, 4, 8), OptionError);
}

TEST(HshFiles, RtiHoldsTheCoefficientsAndTheWebFormatDescribesThePlanes) {
  testing::TempDir tmp;
  const KnownHsh k = WriteKnownCapture(tmp.path(), 3);
  const Hsh& hsh = k.truth;
  WriteRtiFile(hsh, tmp / "h.rti");
  const std::string bytes = ReadFileBytes(tmp / "h.rti", 1 << 20);
  const std::string header = "#HSH1.2\n3\n5 4 3\n9 2 1\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  float scale[9], bias[9];
  std::memcpy(scale, bytes.data() + header.size(), sizeof scale);
  std::memcpy(bias, bytes.data() + header.size() + sizeof scale, sizeof bias);
  const std::size_t data = header.size() + sizeof scale + sizeof bias;
  ASSERT_EQ(bytes.size(), data + hsh.NumTexels() * 27);
  // Rows bottom to top; per texel R's terms, G's, B's; value = byte / 255 * scale + bias.
  for (int y = 0; y < hsh.height; ++y)
    for (int x = 0; x < hsh.width; ++x)
      for (int c = 0; c < 3; ++c)
        for (int j = 0; j < 9; ++j) {
          const std::size_t at =
              data + ((static_cast<std::size_t>(hsh.height - 1 - y) * hsh.width + x) * 3 + c) * 9 +
              j;
          const float value = static_cast<unsigned char>(bytes[at]) / 255.0f * scale[j] + bias[j];
          EXPECT_NEAR(value, hsh.At(static_cast<std::size_t>(y) * hsh.width + x, c)[j],
                      scale[j] / 510.0f + 1e-6f);
        }
  EXPECT_EQ(WriteHshRelightWeb(hsh, tmp / "web"), 10);
  const auto info = nlohmann::json::parse(testing::ReadText(tmp / "web/info.json"));
  EXPECT_EQ(info["type"], "hsh");
  EXPECT_EQ(info["colorspace"], "rgb");
  EXPECT_EQ(info["nplanes"], 27);
  EXPECT_EQ(info["materials"][0]["scale"].size(), 27u);
}

}  // namespace
}  // namespace texlume::ptm
