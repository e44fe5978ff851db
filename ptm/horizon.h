#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace texlume::ptm {

/// Self-shadowing of a sample's relief by horizon mapping (Max 1988; Sloan and
/// Cohen 2000): per texel and azimuth, the elevation above which the relief
/// around it leaves a directional light unblocked. A biquadratic PTM cannot carry
/// cast shadows; a horizon map can, as a visibility factor on the linear light.
///
/// Frames: texel (tangent) frame x right, y up, z out of the surface, as the PTM's
/// lights; images and maps row 0 at the top. Heights are in texel units (one unit
/// is one texel's width), so slopes are dimensionless.

/// Height field (CV_64FC1, texel units, mean 0) whose gradient best fits the
/// normals' slopes in the least-squares sense: the Poisson equation with Neumann
/// boundaries solved by the discrete cosine transform (Simchony, Chellappa and
/// Shao 1990; the non-periodic form of Frankot and Chellappa 1988).
/// `normals_xyz`: row-major, 3 floats per texel, unit vectors in the texel frame;
/// z is clamped to at least `min_normal_z` so grazing normals keep a finite slope.
/// Throws std::invalid_argument for a size mismatch or a map under 2 x 2.
cv::Mat HeightFromNormals(const std::vector<float>& normals_xyz, int width, int height,
                          double min_normal_z = 0.2);

/// Per texel, the horizon elevation (radians, >= 0) in `sectors` azimuths
/// phi_s = 2 pi s / sectors (phi from +x towards +y, texel frame).
struct HorizonMap {
  int width = 0, height = 0, sectors = 0;
  /// Texel-major: `sectors` elevations per texel.
  std::vector<float> elevation_rad;

  std::size_t NumTexels() const { return static_cast<std::size_t>(width) * height; }
  /// The horizon at a light's azimuth (radians), linear between sectors.
  double ElevationAt(std::size_t texel, double azimuth_rad) const;
};

/// The horizon of every texel of `height_texels` (CV_64FC1, texel units): in each
/// sector the largest elevation atan(dh / d) of the relief up to
/// `max_distance_texels` away, read bilinearly along the ray; 0 where nothing rises
/// above the texel. The ray leaving the map sees nothing beyond its edge.
/// `regions` (optional, CV_32SC1 of the map's size; an atlas's charts): a ray from
/// a texel of region >= 0 stops at its first step whose nearest texel is of another
/// region, as at the map's edge (texels of region < 0, gutters, see everything).
/// Throws std::invalid_argument for sectors outside [4, 64], a distance outside
/// [1, 4096] or regions of another size or type.
HorizonMap ComputeHorizonMap(const cv::Mat& height_texels, int sectors, int max_distance_texels,
                             const cv::Mat& regions = cv::Mat());

/// The ramp of HorizonVisibility: 0 at `penumbra_rad` / 2 below the horizon, 1 as far
/// above it (elevations in radians).
double VisibilityAboveHorizon(double light_elevation_rad, double horizon_elevation_rad,
                              double penumbra_rad);

/// The fraction of a directional light (unit, texel frame) that reaches the texel:
/// 0 below the horizon, 1 above it, a linear ramp of `penumbra_rad` across it (a
/// texel's footprint and a light's size soften the edge).
double HorizonVisibility(const HorizonMap& horizon, std::size_t texel, const Eigen::Vector3d& light,
                         double penumbra_rad);

/// Where a directional light (unit, texel frame) falls among a horizon map's
/// `sectors` azimuths, and its elevation: found once per light, read at many texels.
struct LightAmongSectors {
  LightAmongSectors(const Eigen::Vector3d& light, int sectors);
  int s0 = 0, s1 = 0;  ///< the sectors either side of the light's azimuth
  double f = 0.0;      ///< the weight of s1
  double elevation_rad = 0.0;
  /// The horizon at the light's azimuth, from a texel's elevations in s0 and s1.
  double Horizon(double elevation_s0, double elevation_s1) const {
    return elevation_s0 * (1.0 - f) + elevation_s1 * f;
  }
};

/// A sample's self-shadowing: its horizon map and how much light a shadow keeps.
/// Relit, a texel's linear light is multiplied by LightFactor (RelightShadowed in
/// shadowed_fit.h).
struct SelfShadowing {
  HorizonMap horizon;
  /// The integrated PTM normals' heights times this are the relief's (texel units):
  /// a biquadratic's normals are flatter than the surface's.
  double height_scale = 1.0;
  /// Linear fraction of the lit light that a shadowed texel keeps (ambient and
  /// interreflected light). [0, 1].
  double shadow_floor = 1.0;
  /// Width of the shadow's edge in light elevation, radians. (0, pi / 4].
  double penumbra_rad = 0.07;

  /// v + (1 - v) shadow_floor, v the horizon's visibility of the light (unit, texel frame).
  double LightFactor(std::size_t texel, const Eigen::Vector3d& light) const;
  /// The light factor at a visibility v in [0, 1]: v + (1 - v) shadow_floor.
  double LightFactorAt(double visibility) const {
    return visibility + (1.0 - visibility) * shadow_floor;
  }
  /// The mean light factor over a cell of texels whose horizons at the light's azimuth
  /// have this mean and variance (radians, radians^2): the horizons taken as spread
  /// evenly about their mean, so the ramp widens to sqrt(penumbra^2 + 12 variance). At
  /// variance 0 it is LightFactor's.
  double CellLightFactor(double light_elevation_rad, double horizon_mean_rad,
                         double horizon_variance) const;
};

/// The share of light a self-shadowing takes from lights low over the surface: the
/// mean of 1 - LightFactor over the texels `counted` (empty: all), the sectors'
/// azimuths and light elevations of 10, 15, 20, 25 and 30 degrees, with the relief's
/// heights times `relief_gain` (the horizon's tangents times it, as a scaled height
/// field's horizon is: the steepest rise keeps its place).
double LowLightShadowLoss(const SelfShadowing& shadowing, const std::vector<char>& counted,
                          double relief_gain = 1.0);

/// The relief of `shadowing` with its heights times `gain` > 0: every horizon's tangent
/// and the height scale times it. Returns `gain`.
double ScaleRelief(SelfShadowing& shadowing, double gain);

/// Scales the relief of `shadowing` (heights times m: horizon tangents and height_scale)
/// so that its LowLightShadowLoss over `counted` equals `target_loss`, m in [1/4, 4]
/// (clamped there when the target is out of reach; 1, the relief unchanged, when the
/// target is 0 or the map casts no shadow at any gain). Returns m. A synthesised atlas's
/// integrated normals, blended and resampled, are flatter than its sample's: matched,
/// the model casts the sample's share of shadow.
double MatchLowLightShadowLoss(SelfShadowing& shadowing, const std::vector<char>& counted,
                               double target_loss);

/// A horizon file: OpenEXR, one channel per sector ("horizon.00", "horizon.01", ...:
/// elevation in radians), float attributes texlume:height_scale, texlume:shadow_floor
/// and texlume:penumbra_rad. Written atomically.
void WriteSelfShadowingExr(const SelfShadowing& shadowing, const std::filesystem::path& path);
/// Throws InputError naming the file when it is not a horizon file, a channel or
/// attribute is missing, or a value is out of range (elevations in [0, pi / 2]).
SelfShadowing ReadSelfShadowingExr(const std::filesystem::path& path);
/// The same, also refused unless the map is `width` x `height`: the size of
/// `of_what` ("the sample", "its atlas", "the PTM x.ptm"), which the message names.
SelfShadowing ReadSelfShadowingExr(const std::filesystem::path& path, int width, int height,
                                   const std::string& of_what);

}  // namespace texlume::ptm
