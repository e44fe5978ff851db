#pragma once

#include <Eigen/Core>
#include <array>
#include <utility>
#include <vector>

namespace texlume::ptm {

/// Lights lower than this (degrees above the tangent plane) are evaluated at this
/// elevation and faded linearly in l_z to 0 at the horizon: RTI domes rarely
/// light below it, and the biquadratic overshoots there. Recorded in the model's
/// manifest and glTF extras so that viewers do the same.
inline constexpr double kHorizonElevationDeg = 15.0;

/// How a relit texel answers a light beyond its biquadratic, as the photos of
/// the object showed it (synth::EstimatePhotometry, docs/synth.md):
///  - a factor on each light's linear contribution that depends on the light's
///    elevation in the texel's frame (piecewise linear between knots every
///    kKnotSpacingDeg degrees from 0 to 90): a biquadratic fitted over a dome
///    is too dark at some elevations and too bright at others, and the object's
///    photos, taken from other directions than the sample's camera, add
///    highlights and sheen that the sample's PTM cannot hold;
///  - ambient light: `ambient` times the texel's linear value under a unit
///    light at the zenith, added whatever the lights (the unlit side of an
///    object is not black in a photo);
///  - how a rough surface's brightness depends on the view (Oren and Nayar
///    1994, the qualitative model, eq. 30): each light's linear contribution
///    times 1 + (B / A) max(0, cos(phi_r - phi_i)) sin(alpha) tan(beta), with
///    alpha = max(theta_i, theta_r), beta = min(theta_i, theta_r). The sample's
///    camera looks down its normal (theta_r = 0), where the term is 0; seen
///    from the light's side at a slant the relief shows its lit slopes and
///    hides its shadows, and the surface is brighter.
/// The default is the identity: the biquadratic alone, no ambient.
struct LightResponse {
  static constexpr int kKnots = 10;
  static constexpr double kKnotSpacingDeg = 10.0;
  /// tan(beta) is taken at most at this angle (degrees): at grazing light and
  /// view the term stays finite.
  static constexpr double kMaxBetaDeg = 80.0;
  std::array<double, kKnots> elevation_factor{1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  double ambient = 0.0;
  /// Oren and Nayar's B / A (0: a view-independent response; [0, 2]).
  double oren_nayar_b_over_a = 0.0;

  /// The factor at a light direction's z in the texel frame (sin of its
  /// elevation), piecewise linear in the elevation; 0 at or below the horizon.
  double FactorAt(double l_z) const;
  /// 1 + oren_nayar_b_over_a * OrenNayarTerm(light, view): the view's factor on a
  /// light's linear contribution (unit directions in the texel frame).
  double ViewFactorAt(const Eigen::Vector3d& light, const Eigen::Vector3d& view) const;
  bool IsIdentity() const;
  /// Throws OptionError unless every factor is finite and in [0, 10], the
  /// ambient finite and in [0, 1] and the Oren-Nayar ratio finite and in [0, 2].
  void Check() const;
};

/// Oren and Nayar's view term max(0, cos(phi_r - phi_i)) sin(alpha) tan(beta)
/// (their eq. 30 over A; beta at most LightResponse::kMaxBetaDeg) for unit light
/// and view directions in a frame whose z is the normal; 0 when either is at or
/// below the tangent plane, or along the normal.
double OrenNayarTerm(const Eigen::Vector3d& light, const Eigen::Vector3d& view);

/// The weights of the knots at an elevation (degrees): two neighbours, linear.
struct KnotWeights {
  int lower = 0;
  double upper_weight = 0.0;  ///< weight of knot lower + 1; lower's is 1 - it
};
KnotWeights KnotWeightsAt(double elevation_deg);

/// A light as a texel answers it: the direction at which to evaluate the
/// biquadratic (clamped to kHorizonElevationDeg, same azimuth) and the weight
/// of its linear value (intensity x horizon fade x elevation factor x the view's
/// factor, `view_in_frame` the unit direction towards the viewer); weight 0 at
/// or below the horizon. A view along the normal has factor 1.
struct EffectiveLight {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  double weight = 0.0;
};
EffectiveLight Effective(const Eigen::Vector3d& light_in_frame, double intensity,
                         const LightResponse& response, const Eigen::Vector3d& view_in_frame);

/// Every light as the texel answers it seen from `view_in_frame` (Effective; those
/// of weight 0 left out), then the ambient light as a light at the zenith of weight
/// `response.ambient` (when > 0): the linear value is the weighted sum of the
/// biquadratic's linear values at the directions. `source`, when given, receives per
/// effective light the index in `lights_in_frame` it came from, -1 for the ambient
/// light.
std::vector<EffectiveLight> EffectiveLights(
    const std::vector<std::pair<Eigen::Vector3d, double>>& lights_in_frame,
    const LightResponse& response, const Eigen::Vector3d& view_in_frame,
    std::vector<int>* source = nullptr);

}  // namespace texlume::ptm
