#include "synth/coefficient_correction.h"

#include <gtest/gtest.h>

#include <random>

#include "core/image_io.h"
#include "ptm/ptm.h"

namespace texlume::synth {
namespace {

TEST(RelitLinearShare, ClampsAsTheRelightingDoes) {
  double slope = -1.0;
  EXPECT_EQ(RelitLinearShare(1.4, &slope), 1.0);  // white, whatever the excess
  EXPECT_EQ(slope, 0.0);
  EXPECT_EQ(RelitLinearShare(1.0, &slope), 1.0);
  EXPECT_EQ(RelitLinearShare(-0.2, &slope), 0.0);  // black
  EXPECT_EQ(slope, 0.0);
  EXPECT_EQ(RelitLinearShare(0.0), 0.0);
}

TEST(RelitLinearShare, DecodesSrgbWithItsSlopeInside) {
  for (const double v : {0.02, 0.2, 0.5, 0.9}) {
    double slope = 0.0;
    EXPECT_EQ(RelitLinearShare(v, &slope), SrgbToLinear(static_cast<float>(v))) << v;
    // d/dv of ((v + 0.055) / 1.055)^2.4 above the linear segment, 1 / 12.92 below.
    const double expected =
        v <= 0.04045 ? 1.0 / 12.92 : 2.4 / 1.055 * std::pow((v + 0.055) / 1.055, 1.4);
    EXPECT_NEAR(slope, expected, 1e-4 * expected) << v;
  }
}

// The pass's prediction of a texel (its lights' shares summed, times the gain,
// encoded) is what PtmSample::Relight gives it, also where a light saturates it:
// bright coefficients under a strong light, and an ambient term.
TEST(RelitLinearShare, SummedOverTheLightsIsTheRelitSample) {
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, 9, 7);
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> a(-0.3f, 1.3f), colour(0.2f, 1.0f);
  for (float& v : p.coefficients) v = a(rng);
  for (float& v : p.colour) v = colour(rng);
  const PtmSample sample(p);
  FaceLighting lighting{
      Eigen::Vector3d::UnitZ(),
      {{Eigen::Vector3d(0.2, 0.1, 0.97), 2.5}, {Eigen::Vector3d(-0.7, 0.3, 0.65), 0.8}},
      {}};
  lighting.response.ambient = 0.1;
  const double gain = 0.8;
  const ReducedPlanes& reduced = sample.Reduced(0);
  const std::vector<cv::Mat> relit = sample.Relight(reduced, lighting, gain);
  const std::vector<ptm::EffectiveLight> lights = sample.LightsOf(lighting).lights;
  int saturated = 0;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      float coefficients[6];
      for (std::size_t m = 0; m < 6; ++m) coefficients[m] = reduced.planes[m].at<float>(y, x);
      for (std::size_t c = 0; c < 3; ++c) {
        const double colour_c = reduced.planes[6 + c].at<float>(y, x);
        double linear = 0.0;
        for (const ptm::EffectiveLight& l : lights) {
          const double display =
              ptm::EvaluatePolynomial(coefficients, l.direction.x(), l.direction.y()) * colour_c;
          saturated += display >= 1.0;
          linear += l.weight * RelitLinearShare(display);
        }
        EXPECT_NEAR(LinearToSrgb(static_cast<float>(gain * linear)), relit[c].at<float>(y, x), 1e-5)
            << x << ", " << y << ", channel " << c;
      }
    }
  EXPECT_GT(saturated, 10);  // the case the pass once predicted black
}

}  // namespace
}  // namespace texlume::synth
