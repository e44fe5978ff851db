#include "ptm/light_response.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"

namespace texlume::ptm {
namespace {

double Sin(double deg) { return std::sin(deg * std::numbers::pi / 180.0); }

TEST(LightResponse, FactorsArePiecewiseLinearInElevationAndZeroBelowTheHorizon) {
  LightResponse r;
  EXPECT_TRUE(r.IsIdentity());
  EXPECT_DOUBLE_EQ(r.FactorAt(Sin(37.0)), 1.0);
  for (int k = 0; k < LightResponse::kKnots; ++k)
    r.elevation_factor[static_cast<std::size_t>(k)] = 1.0 + 0.1 * k;
  EXPECT_FALSE(r.IsIdentity());
  EXPECT_NEAR(r.FactorAt(Sin(30.0)), 1.3, 1e-9);
  EXPECT_NEAR(r.FactorAt(Sin(35.0)), 1.35, 1e-9);
  EXPECT_NEAR(r.FactorAt(Sin(85.0)), 1.85, 1e-9);
  EXPECT_NEAR(r.FactorAt(1.0), 1.9, 1e-9);
  EXPECT_EQ(r.FactorAt(0.0), 0.0);
  EXPECT_EQ(r.FactorAt(-0.3), 0.0);
}

TEST(LightResponse, EffectiveLightsFadeBelowTheHorizonElevationAndAddTheAmbient) {
  LightResponse r;
  r.elevation_factor[4] = 2.0;  // 40 degrees
  r.ambient = 0.05;
  const Eigen::Vector3d at40(std::cos(40.0 * std::numbers::pi / 180.0), 0.0, Sin(40.0));
  const Eigen::Vector3d at5(0.0, std::cos(5.0 * std::numbers::pi / 180.0), Sin(5.0));
  const Eigen::Vector3d below(1.0, 0.0, -0.1);
  const std::vector<EffectiveLight> lights = EffectiveLights(
      {{at40, 0.5}, {at5, 1.0}, {below.normalized(), 3.0}}, r, Eigen::Vector3d::UnitZ());
  ASSERT_EQ(lights.size(), 3u);  // the light below the horizon is left out
  EXPECT_NEAR(lights[0].weight, 0.5 * 2.0, 1e-12);
  EXPECT_TRUE(lights[0].direction.isApprox(at40));
  // 5 degrees: evaluated at the horizon elevation, same azimuth, faded by l_z.
  EXPECT_NEAR(lights[1].direction.z(), Sin(kHorizonElevationDeg), 1e-12);
  EXPECT_NEAR(lights[1].direction.x(), 0.0, 1e-12);
  EXPECT_NEAR(lights[1].direction.norm(), 1.0, 1e-12);
  EXPECT_NEAR(lights[1].weight, Sin(5.0) / Sin(kHorizonElevationDeg) * r.FactorAt(Sin(5.0)), 1e-12);
  EXPECT_TRUE(lights[2].direction.isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_DOUBLE_EQ(lights[2].weight, 0.05);
}

// A unit direction at `elevation_deg` above the tangent plane and `azimuth_deg`.
Eigen::Vector3d At(double elevation_deg, double azimuth_deg) {
  const double e = elevation_deg * std::numbers::pi / 180.0,
               a = azimuth_deg * std::numbers::pi / 180.0;
  return {std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)};
}

TEST(OrenNayarTerm, IsTheModelsViewTermAndVanishesWhereTheSampleCameraLooks) {
  // Light at 30 degrees from the normal, view at 60, same azimuth: sin 60 tan 30.
  EXPECT_NEAR(OrenNayarTerm(At(60, 0), At(30, 0)),
              std::sin(std::numbers::pi / 3) * std::tan(std::numbers::pi / 6), 1e-12);
  // Symmetric in light and view; cos(phi_r - phi_i) scales it.
  EXPECT_NEAR(OrenNayarTerm(At(30, 0), At(60, 0)), OrenNayarTerm(At(60, 0), At(30, 0)), 1e-12);
  EXPECT_NEAR(OrenNayarTerm(At(60, 0), At(30, 60)), 0.5 * OrenNayarTerm(At(60, 0), At(30, 0)),
              1e-12);
  // 0 for a view along the normal (the sample's camera), across azimuths beyond 90
  // degrees apart, and for a light or view below the tangent plane.
  EXPECT_EQ(OrenNayarTerm(At(40, 0), Eigen::Vector3d::UnitZ()), 0.0);
  EXPECT_EQ(OrenNayarTerm(At(40, 0), At(20, 120)), 0.0);
  EXPECT_EQ(OrenNayarTerm(At(-5, 0), At(20, 0)), 0.0);
  EXPECT_EQ(OrenNayarTerm(At(40, 0), At(-5, 0)), 0.0);
  // Grazing light and view: beta held at 80 degrees.
  EXPECT_NEAR(OrenNayarTerm(At(1, 0), At(2, 0)),
              std::sin(89.0 * std::numbers::pi / 180.0) * std::tan(80.0 * std::numbers::pi / 180.0),
              1e-12);
}

TEST(LightResponse, TheViewTermScalesALightAsSeenFromTheView) {
  LightResponse r;
  r.oren_nayar_b_over_a = 0.4;
  const Eigen::Vector3d light = At(40, 10), view = At(35, 30);
  const std::vector<EffectiveLight> seen = EffectiveLights({{light, 1.0}}, r, view);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_NEAR(seen[0].weight, 1.0 + 0.4 * OrenNayarTerm(light, view), 1e-12);
  EXPECT_GT(seen[0].weight, 1.1);
  // From along the normal, as the sample was captured: the light as it is.
  EXPECT_NEAR(EffectiveLights({{light, 1.0}}, r, Eigen::Vector3d::UnitZ())[0].weight, 1.0, 1e-12);
  EXPECT_FALSE(r.IsIdentity());
  r.oren_nayar_b_over_a = 2.5;
  EXPECT_THROW(r.Check(), OptionError);
}

TEST(LightResponse, CheckRefusesFactorsAndAmbientOutOfRange) {
  LightResponse r;
  EXPECT_NO_THROW(r.Check());
  r.elevation_factor[3] = std::nan("");
  EXPECT_THROW(r.Check(), OptionError);
  r.elevation_factor[3] = 11.0;
  EXPECT_THROW(r.Check(), OptionError);
  r.elevation_factor[3] = 1.0;
  r.ambient = -0.1;
  EXPECT_THROW(r.Check(), OptionError);
}

}  // namespace
}  // namespace texlume::ptm
