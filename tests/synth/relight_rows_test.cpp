#include "synth/relight_rows.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <random>

#include "synth/colour_sample.h"
#include "synth/material_sample.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {
namespace {

// Raw coefficient planes (then LRGB colour planes) of random values, seeded, wide
// enough that relit values fall below 0, in both linear segments and above 1.
std::vector<cv::Mat> RandomRawPlanes(ptm::PtmFormat format, cv::Size size, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> a(-0.6f, 0.6f), colour(0.0f, 1.2f);
  const bool lrgb = format == ptm::PtmFormat::kLrgb;
  std::vector<cv::Mat> planes(lrgb ? 9 : 18);
  for (std::size_t i = 0; i < planes.size(); ++i) {
    planes[i] = cv::Mat(size, CV_32FC1);
    for (float& v : cv::Mat_<float>(planes[i])) v = (lrgb && i >= 6) ? colour(rng) : a(rng);
  }
  return planes;
}

std::vector<ptm::EffectiveLight> Lights() {
  return {{Eigen::Vector3d(0.5, -0.3, 0.81).normalized(), 0.8},
          {Eigen::Vector3d(-0.9, 0.2, 0.2).normalized(), 1.7},
          {Eigen::Vector3d::UnitZ(), 0.15}};  // an ambient light, as EffectiveLights adds it
}

// A PTM of random coefficients in [-0.4, 0.6] and colour in [0.1, 1], seeded.
ptm::Ptm RandomPtm(ptm::PtmFormat format, int width, int height, unsigned seed) {
  ptm::Ptm p;
  p.Resize(format, width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> a(-0.4f, 0.6f), colour(0.1f, 1.0f);
  for (float& v : p.coefficients) v = a(rng);
  for (float& v : p.colour) v = colour(rng);
  return p;
}

// Two lights, an ambient light and an elevation factor.
FaceLighting TwoLightsWithResponse() {
  FaceLighting lighting{
      Eigen::Vector3d::UnitZ(),
      {{Eigen::Vector3d(0.3, 0.4, 0.866), 1.1}, {Eigen::Vector3d(-0.8, 0.5, 0.33), 0.6}},
      {}};
  lighting.response.ambient = 0.12;
  lighting.response.elevation_factor[2] = 0.7;
  return lighting;
}

// The relit cells, bit for bit, against RelightEffective cell by cell.
void ExpectSameAsPerCell(ptm::PtmFormat format, const std::vector<cv::Mat>& planes,
                         const std::array<cv::Mat, 3>& relit,
                         const std::vector<ptm::EffectiveLight>& lights, double gain) {
  const bool lrgb = format == ptm::PtmFormat::kLrgb;
  std::vector<float> texel(planes.size());
  const float ones[3] = {1.0f, 1.0f, 1.0f};
  int compared = 0;
  for (int y = 0; y < planes[0].rows; ++y)
    for (int x = 0; x < planes[0].cols; ++x) {
      for (std::size_t i = 0; i < planes.size(); ++i) texel[i] = planes[i].at<float>(y, x);
      const Eigen::Vector3f expected =
          RelightEffective(texel.data(), lrgb ? texel.data() + 6 : ones, format, lights, gain);
      for (int c = 0; c < 3; ++c) {
        const float got = relit[static_cast<std::size_t>(c)].at<float>(y, x);
        ASSERT_EQ(std::memcmp(&got, &expected[c], sizeof(float)), 0)
            << "cell (" << x << ", " << y << ") channel " << c << ": " << got << " against "
            << expected[c];
        ++compared;
      }
    }
  EXPECT_EQ(compared, 3 * planes[0].rows * planes[0].cols);
}

// Rows of 1 to 37 cells (whole vector steps and the rest), both PTM formats.
TEST(PtmRowRelighter, IsRelightEffectiveToTheBit) {
  for (const ptm::PtmFormat format : {ptm::PtmFormat::kLrgb, ptm::PtmFormat::kRgb})
    for (const int cols : {1, 7, 8, 9, 16, 37}) {
      SCOPED_TRACE(cols);
      const std::vector<cv::Mat> planes = RandomRawPlanes(format, cv::Size(cols, 3), 11);
      std::array<cv::Mat, 3> relit;
      for (cv::Mat& m : relit) m = cv::Mat(3, cols, CV_32FC1);
      PtmRowRelighter rows(format, Lights(), 1.4);
      std::vector<const float*> in(planes.size());
      for (int y = 0; y < 3; ++y) {
        for (std::size_t i = 0; i < planes.size(); ++i) in[i] = planes[i].ptr<float>(y);
        rows.Relight(in.data(), cols,
                     {relit[0].ptr<float>(y), relit[1].ptr<float>(y), relit[2].ptr<float>(y)});
      }
      ExpectSameAsPerCell(format, planes, relit, Lights(), 1.4);
    }
}

// A PtmSample relights through the rows: its reduced planes relit, cell by cell, as
// RelightMixture relights them under the face's lights and response.
TEST(PtmRowRelighter, IsWhatAPtmSampleRelightsWith) {
  for (const ptm::PtmFormat format : {ptm::PtmFormat::kLrgb, ptm::PtmFormat::kRgb}) {
    const ptm::Ptm p = RandomPtm(format, 21, 13, 5);
    const PtmSample sample(p);
    const FaceLighting lighting = TwoLightsWithResponse();
    const ReducedPlanes& reduced = sample.Reduced(2);
    const std::vector<cv::Mat> relit = sample.Relight(reduced, lighting, 0.9);
    const std::vector<ptm::EffectiveLight> lights =
        ptm::EffectiveLights(lighting.lights, lighting.response, lighting.view_in_frame);
    ASSERT_EQ(lights.size(), 3u);
    ExpectSameAsPerCell(format, reduced.planes, {relit[0], relit[1], relit[2]}, lights, 0.9);
  }
}

// A sample's window relighter writes, at each window, the cells Relight gives for
// the whole reduced sample, bit for bit, and leaves every other cell alone.
void ExpectWindowsAsTheWhole(const MaterialSample& sample, const ReducedPlanes& reduced,
                             const FaceLighting& lighting, double gain) {
  const std::vector<cv::Mat> whole = sample.Relight(reduced, lighting, gain);
  const cv::Size size = reduced.planes[0].size();
  std::array<cv::Mat, 3> out;
  for (cv::Mat& m : out) m = cv::Mat(size, CV_32FC1, cv::Scalar(-7.0f));
  const std::unique_ptr<WindowRelighter> relighter = sample.RelighterOf(reduced, lighting, gain);
  // Overlapping windows, one cell wide, and at the bottom right corner.
  const std::vector<cv::Rect> windows = {
      {0, 0, 5, 3}, {3, 2, 9, 4}, {7, 1, 1, 6}, {size.width - 7, size.height - 2, 7, 2}};
  cv::Mat inside = cv::Mat::zeros(size, CV_8UC1);
  for (const cv::Rect& w : windows) {
    relighter->Relight(w, out);
    inside(w).setTo(1);
  }
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        const float got = out[static_cast<std::size_t>(c)].at<float>(y, x);
        const float expected = inside.at<unsigned char>(y, x)
                                   ? whole[static_cast<std::size_t>(c)].at<float>(y, x)
                                   : -7.0f;
        ASSERT_EQ(std::memcmp(&got, &expected, sizeof(float)), 0)
            << "cell (" << x << ", " << y << ") channel " << c << ": " << got << " against "
            << expected;
      }
}

TEST(WindowRelighter, PtmWindowsAreTheWholeRelitSample) {
  for (const ptm::PtmFormat format : {ptm::PtmFormat::kLrgb, ptm::PtmFormat::kRgb}) {
    const ptm::Ptm p = RandomPtm(format, 37, 23, 9);
    const PtmSample sample(p);
    ExpectWindowsAsTheWhole(sample, sample.Reduced(1), TwoLightsWithResponse(), 0.9);
  }
}

// A colour sample's windows (Relight per window) are its whole relit sample too.
TEST(WindowRelighter, ColourWindowsAreTheWholeRelitSample) {
  cv::Mat display(20, 29, CV_32FC3);
  cv::randu(display, cv::Scalar::all(0.0), cv::Scalar::all(1.0));
  const ColourSample sample(display);
  ExpectWindowsAsTheWhole(sample, sample.Reduced(0), TwoLightsWithResponse(), 0.83);
}

// With the relief's shadows each cell has its own lights: the windows are relit by
// Relight itself, and still read the horizon at their own cells.
TEST(WindowRelighter, ShadowedPtmWindowsAreTheWholeRelitSample) {
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, 24, 20);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> a(-0.3f, 0.6f), colour(0.1f, 1.0f), horizon(0.0f, 0.9f);
  for (float& v : p.coefficients) v = a(rng);
  for (float& v : p.colour) v = colour(rng);
  ptm::SelfShadowing shadowing;
  shadowing.horizon = {24, 20, 8, std::vector<float>(24 * 20 * 8)};
  for (float& e : shadowing.horizon.elevation_rad) e = horizon(rng);
  shadowing.shadow_floor = 0.25;
  shadowing.penumbra_rad = 0.07;
  const PtmSample sample(p, &shadowing);
  ExpectWindowsAsTheWhole(sample, sample.Reduced(0), TwoLightsWithResponse(), 1.1);
}

}  // namespace
}  // namespace texlume::synth
