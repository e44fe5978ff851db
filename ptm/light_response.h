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
///    object is not black in a photo).
/// The default is the identity: the biquadratic alone, no ambient.
struct LightResponse {
  static constexpr int kKnots = 10;
  static constexpr double kKnotSpacingDeg = 10.0;
  std::array<double, kKnots> elevation_factor{1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  double ambient = 0.0;

  /// The factor at a light direction's z in the texel frame (sin of its
  /// elevation), piecewise linear in the elevation; 0 at or below the horizon.
  double FactorAt(double l_z) const;
  bool IsIdentity() const;
  /// Throws OptionError unless every factor is finite and in [0, 10] and the
  /// ambient finite and in [0, 1].
  void Check() const;
};

/// The weights of the knots at an elevation (degrees): two neighbours, linear.
struct KnotWeights {
  int lower = 0;
  double upper_weight = 0.0;  ///< weight of knot lower + 1; lower's is 1 - it
};
KnotWeights KnotWeightsAt(double elevation_deg);

/// A light as a texel answers it: the direction at which to evaluate the
/// biquadratic (clamped to kHorizonElevationDeg, same azimuth) and the weight
/// of its linear value (intensity x horizon fade x elevation factor); weight 0
/// at or below the horizon.
struct EffectiveLight {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  double weight = 0.0;
};
EffectiveLight Effective(const Eigen::Vector3d& light_in_frame, double intensity,
                         const LightResponse& response);

/// Every light as the texel answers it (Effective; those of weight 0 left out),
/// then the ambient light as a light at the zenith of weight `response.ambient`
/// (when > 0): the linear value is the weighted sum of the biquadratic's linear
/// values at the directions. `source`, when given, receives per effective light the
/// index in `lights_in_frame` it came from, -1 for the ambient light.
std::vector<EffectiveLight> EffectiveLights(
    const std::vector<std::pair<Eigen::Vector3d, double>>& lights_in_frame,
    const LightResponse& response, std::vector<int>* source = nullptr);

}  // namespace texlume::ptm
