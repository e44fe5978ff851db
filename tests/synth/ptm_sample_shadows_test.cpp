// A PTM sample relit with the relief's self-shadowing (issue 29): what the
// synthesis compares with the photos casts the shadows the render casts.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <utility>

#include "core/srgb.h"
#include "ptm/horizon.h"
#include "synth/colour_sample.h"
#include "synth/material_sample.h"

namespace texlume::synth {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A light at an elevation and azimuth (degrees), texel frame.
Eigen::Vector3d LightAt(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * kDeg, a = azimuth_deg * kDeg;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

// A 16 x 16 grey Lambertian PTM (LRGB).
ptm::Ptm GreySample() {
  return LambertianPtm(cv::Mat(16, 16, CV_32FC3, cv::Scalar(0.6, 0.5, 0.4)));
}

// Its self-shadowing: every sector's horizon `horizon_deg(x)` at column x.
template <typename HorizonOfColumn>
ptm::SelfShadowing Shadowing(HorizonOfColumn horizon_deg) {
  ptm::SelfShadowing s;
  s.horizon = {16, 16, 8, std::vector<float>(16 * 16 * 8)};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int k = 0; k < 8; ++k)
        s.horizon.elevation_rad[static_cast<std::size_t>((y * 16 + x) * 8 + k)] =
            static_cast<float>(horizon_deg(x) * kDeg);
  s.shadow_floor = 0.25;
  s.penumbra_rad = 4.0 * kDeg;
  return s;
}

// The mean linear value of channel 0 of a relit sample.
double MeanLinear(const std::vector<cv::Mat>& relit) {
  double sum = 0.0;
  for (int y = 0; y < relit[0].rows; ++y)
    for (int x = 0; x < relit[0].cols; ++x) sum += srgb::ToLinear(relit[0].at<float>(y, x));
  return sum / static_cast<double>(relit[0].total());
}

TEST(LightAmongSectors, ReadsTheHorizonAsTheMapDoes) {
  ptm::HorizonMap map{1, 1, 16, {}};
  for (int s = 0; s < 16; ++s) map.elevation_rad.push_back(0.05f * static_cast<float>(s));
  for (const double azimuth_deg : {0.0, 10.0, 100.0, 200.0, 350.0, -30.0}) {
    const Eigen::Vector3d l = LightAt(25.0, azimuth_deg);
    const ptm::LightAmongSectors at(l, 16);
    EXPECT_NEAR(at.Horizon(map.elevation_rad[static_cast<std::size_t>(at.s0)],
                           map.elevation_rad[static_cast<std::size_t>(at.s1)]),
                map.ElevationAt(0, std::atan2(l.y(), l.x())), 1e-9)
        << azimuth_deg;
    EXPECT_NEAR(at.elevation_rad, 25.0 * kDeg, 1e-9);
  }
}

// Above the horizon a light is the unshadowed sample's; below it only the shadow
// floor of it is left, and the ambient light casts no shadow.
TEST(PtmSampleShadows, EachLightIsTimesTheReliefsLightFactorAndAmbientIsNot) {
  const ptm::Ptm ptm = GreySample();
  const ptm::SelfShadowing shadowing = Shadowing([](int) { return 30.0; });
  const PtmSample plain(ptm), shadowed(ptm, &shadowing);
  EXPECT_TRUE(shadowed.CastsShadows());
  EXPECT_FALSE(plain.CastsShadows());
  const auto relit = [&](const PtmSample& s, const FaceLighting& lighting) {
    return MeanLinear(s.Relight(s.Reduced(0), lighting, 1.0));
  };
  const FaceLighting high{Eigen::Vector3d::UnitZ(), {{LightAt(60.0, 40.0), 1.0}}, {}};
  EXPECT_NEAR(relit(shadowed, high), relit(plain, high), 1e-6);
  const FaceLighting low{Eigen::Vector3d::UnitZ(), {{LightAt(20.0, 220.0), 1.0}}, {}};
  ASSERT_GT(relit(plain, low), 0.02);
  EXPECT_NEAR(relit(shadowed, low), 0.25 * relit(plain, low), 2e-4);
  FaceLighting ambient_only{Eigen::Vector3d::UnitZ(), {}, {}};
  ambient_only.response.ambient = 0.2;
  FaceLighting low_and_ambient = low;
  low_and_ambient.response.ambient = 0.2;
  EXPECT_NEAR(relit(shadowed, low_and_ambient),
              0.25 * relit(plain, low) + relit(plain, ambient_only), 2e-4);
  // The gains' mean relights with the same shadows.
  EXPECT_NEAR(shadowed.RelitLinearSum(low, 100), 0.25 * plain.RelitLinearSum(low, 100),
              1e-3 * plain.RelitLinearSum(low, 100));
}

// At full resolution a texel is shadowed exactly as SelfShadowing::LightFactor has it,
// its horizon interpolated between sectors that differ.
TEST(PtmSampleShadows, ATexelsLightFactorIsTheHorizonMapsBetweenUnlikeSectors) {
  const ptm::Ptm ptm = GreySample();
  ptm::SelfShadowing shadowing = Shadowing([](int) { return 0.0; });
  for (std::size_t i = 0; i < shadowing.horizon.elevation_rad.size(); ++i)
    shadowing.horizon.elevation_rad[i] = static_cast<float>((i % 2 ? 40.0 : 0.0) * kDeg);
  const PtmSample plain(ptm), shadowed(ptm, &shadowing);
  // Sectors are 45 degrees apart: between sector 0 (0) and 1 (40 degrees) the horizon
  // rises from 0 to 40 degrees.
  for (const auto& [elevation_deg, azimuth_deg] :
       {std::pair{25.0, 22.5}, {15.0, 22.5}, {21.0, 22.5}, {30.0, 40.0}, {10.0, 5.0}}) {
    const Eigen::Vector3d l = LightAt(elevation_deg, azimuth_deg);
    const FaceLighting lighting{Eigen::Vector3d::UnitZ(), {{l, 1.0}}, {}};
    EXPECT_NEAR(
        MeanLinear(shadowed.Relight(shadowed.Reduced(0), lighting, 1.0)),
        shadowing.LightFactor(0, l) * MeanLinear(plain.Relight(plain.Reduced(0), lighting, 1.0)),
        2e-4)
        << elevation_deg << " " << azimuth_deg;
  }
}

// A reduced cell holding texels in shadow and texels lit is lit in proportion:
// the horizon's mean and spread over the cell stand for its texels.
TEST(PtmSampleShadows, AReducedCellIsLitInProportionToItsLitTexels) {
  const ptm::Ptm ptm = GreySample();
  // Every other column behind a 40-degree horizon: half of each 2 x 2 cell.
  const ptm::SelfShadowing shadowing = Shadowing([](int x) { return x % 2 ? 40.0 : 0.0; });
  const PtmSample plain(ptm), shadowed(ptm, &shadowing);
  const ReducedPlanes& half = shadowed.Reduced(4);  // 2^(-4/4): 8 x 8 cells
  ASSERT_EQ(half.planes[0].cols, 8);
  for (const double elevation_deg : {20.0, 80.0}) {
    const FaceLighting lighting{Eigen::Vector3d::UnitZ(), {{LightAt(elevation_deg, 0.0), 1.0}}, {}};
    const double full = MeanLinear(shadowed.Relight(shadowed.Reduced(0), lighting, 1.0));
    const double reduced = MeanLinear(shadowed.Relight(half, lighting, 1.0));
    EXPECT_NEAR(reduced, full, 0.02 * full) << elevation_deg;
  }
  // At 30 degrees half the texels are still lit: the even spread the model takes
  // for this cell's two horizons makes it 17 % too bright; the mean horizon (20
  // degrees) alone would light the whole cell, 60 % too bright.
  const FaceLighting at30{Eigen::Vector3d::UnitZ(), {{LightAt(30.0, 0.0), 1.0}}, {}};
  const double full30 = MeanLinear(shadowed.Relight(shadowed.Reduced(0), at30, 1.0));
  EXPECT_NEAR(MeanLinear(shadowed.Relight(half, at30, 1.0)), full30, 0.2 * full30);
  // Half lit at 20 degrees: (1 + 0.25) / 2 of the unshadowed light.
  const FaceLighting at20{Eigen::Vector3d::UnitZ(), {{LightAt(20.0, 0.0), 1.0}}, {}};
  EXPECT_NEAR(MeanLinear(shadowed.Relight(half, at20, 1.0)),
              0.625 * MeanLinear(plain.Relight(plain.Reduced(4), at20, 1.0)), 2e-3);
}

}  // namespace
}  // namespace texlume::synth
