#include "ptm/light_response.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/errors.h"

namespace texlume::ptm {

KnotWeights KnotWeightsAt(double elevation_deg) {
  const double k = std::clamp(elevation_deg, 0.0, 90.0) / LightResponse::kKnotSpacingDeg;
  KnotWeights w;
  w.lower = std::min(static_cast<int>(k), LightResponse::kKnots - 2);
  w.upper_weight = std::clamp(k - w.lower, 0.0, 1.0);
  return w;
}

double LightResponse::FactorAt(double l_z) const {
  if (!(l_z > 0.0)) return 0.0;
  const double elevation_deg = std::asin(std::min(1.0, l_z)) * 180.0 / std::numbers::pi;
  const KnotWeights w = KnotWeightsAt(elevation_deg);
  const auto lower = static_cast<std::size_t>(w.lower);
  return (1.0 - w.upper_weight) * elevation_factor[lower] +
         w.upper_weight * elevation_factor[lower + 1];
}

double OrenNayarTerm(const Eigen::Vector3d& light, const Eigen::Vector3d& view) {
  if (!(light.z() > 0.0) || !(view.z() > 0.0)) return 0.0;
  // cos(phi_r - phi_i) from the directions' parts in the tangent plane.
  const double light_xy = std::hypot(light.x(), light.y()),
               view_xy = std::hypot(view.x(), view.y());
  if (light_xy < 1e-12 || view_xy < 1e-12) return 0.0;
  const double cos_azimuth = (light.x() * view.x() + light.y() * view.y()) / (light_xy * view_xy);
  if (!(cos_azimuth > 0.0)) return 0.0;
  const double theta_i = std::acos(std::min(1.0, light.z()));
  const double theta_r = std::acos(std::min(1.0, view.z()));
  const double alpha = std::max(theta_i, theta_r);
  const double beta =
      std::min({theta_i, theta_r, LightResponse::kMaxBetaDeg * std::numbers::pi / 180.0});
  return cos_azimuth * std::sin(alpha) * std::tan(beta);
}

double LightResponse::ViewFactorAt(const Eigen::Vector3d& light,
                                   const Eigen::Vector3d& view) const {
  if (oren_nayar_b_over_a == 0.0) return 1.0;
  return 1.0 + oren_nayar_b_over_a * OrenNayarTerm(light, view);
}

bool LightResponse::IsIdentity() const {
  return ambient == 0.0 && oren_nayar_b_over_a == 0.0 &&
         std::all_of(elevation_factor.begin(), elevation_factor.end(),
                     [](double f) { return f == 1.0; });
}

void LightResponse::Check() const {
  for (double f : elevation_factor)
    if (!(std::isfinite(f) && f >= 0.0 && f <= 10.0))
      throw OptionError("light response: an elevation factor is not in [0, 10]");
  if (!(std::isfinite(ambient) && ambient >= 0.0 && ambient <= 1.0))
    throw OptionError("light response: ambient is not in [0, 1]");
  if (!(std::isfinite(oren_nayar_b_over_a) && oren_nayar_b_over_a >= 0.0 &&
        oren_nayar_b_over_a <= 2.0))
    throw OptionError("light response: the Oren-Nayar ratio B / A is not in [0, 2]");
}

EffectiveLight Effective(const Eigen::Vector3d& light_in_frame, double intensity,
                         const LightResponse& response, const Eigen::Vector3d& view_in_frame) {
  static const double z_horizon = std::sin(kHorizonElevationDeg * std::numbers::pi / 180.0);
  EffectiveLight out;
  const Eigen::Vector3d& l = light_in_frame;
  if (!(l.z() > 0.0)) return out;
  out.direction = l;
  double fall = 1.0;
  if (l.z() < z_horizon) {
    // Below the horizon elevation the biquadratic is extrapolated beyond any
    // capture light and overshoots: its value there, fading with l_z.
    fall = l.z() / z_horizon;
    const double r = std::hypot(l.x(), l.y());
    const double s = std::sqrt(1.0 - z_horizon * z_horizon) / r;
    out.direction = Eigen::Vector3d(l.x() * s, l.y() * s, z_horizon);
  }
  out.weight =
      intensity * fall * response.FactorAt(l.z()) * response.ViewFactorAt(l, view_in_frame);
  return out;
}

std::vector<EffectiveLight> EffectiveLights(
    const std::vector<std::pair<Eigen::Vector3d, double>>& lights_in_frame,
    const LightResponse& response, const Eigen::Vector3d& view_in_frame, std::vector<int>* source) {
  std::vector<EffectiveLight> out;
  if (source) source->clear();
  for (std::size_t k = 0; k < lights_in_frame.size(); ++k) {
    const auto& [l, intensity] = lights_in_frame[k];
    const EffectiveLight e = Effective(l, intensity, response, view_in_frame);
    if (e.weight <= 0.0) continue;
    out.push_back(e);
    if (source) source->push_back(static_cast<int>(k));
  }
  if (response.ambient > 0.0) {
    out.push_back({Eigen::Vector3d::UnitZ(), response.ambient});
    if (source) source->push_back(-1);
  }
  return out;
}

}  // namespace texlume::ptm
