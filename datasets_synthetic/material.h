#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "datasets_synthetic/noise.h"
#include "ptm/ptm.h"

namespace texlume::datasets {

/// The procedural materials of the synthetic scenes (paper 003 §4 uses
/// displacement-mapped rough surfaces; these add structure and direction).
enum class MaterialKind {
  kStone,    ///< isotropic stone / plaster: cells (stones) with cracks and fractal roughness
  kBrick,    ///< running-bond brick wall: raised bricks, recessed mortar joints (anisotropic)
  kGrooves,  ///< strongly directional: wavy parallel grooves along v, like carved wood grain
};
std::string_view MaterialKindName(MaterialKind kind);  ///< "stone", "brick", "grooves"
std::optional<MaterialKind> MaterialKindFromName(std::string_view name);

/// Settings of a material. Lengths are world units of the scene (the material's
/// physical scale), so a sample and an object made of it share feature sizes.
struct MaterialOptions {
  MaterialKind kind = MaterialKind::kStone;
  /// World units per texel of the material sample and ground-truth maps. (0, 1].
  double texel_size = 0.002;
  /// Peak-to-peak relief of the height field, world units; 0 makes it flat. [0, 1].
  double relief_height = 0.006;
  /// Multiplies the kind's feature sizes (stone cells 0.06, bricks 0.24 x 0.08 with
  /// 0.012 joints, groove period 0.03 world units). (0, 100].
  double feature_scale = 1.0;
  /// Blinn-Phong specular coefficient added to the Lambertian albedo; 0 = matte. [0, 1].
  double specular = 0.0;
  /// Multiplies the albedo (0.05 makes a near-black glossy material). [0, 1].
  double albedo_scale = 1.0;
  /// Blinn-Phong exponent: the specular lobe's roughness (lower is rougher; 40 is
  /// about a microfacet roughness of 0.22). [1, 10000].
  double shininess = 40.0;
  /// Sheen: a white Fresnel-like term strongest at grazing angles between light
  /// and viewer, sheen (1 - l.h)^5 n.l, as on dusty or fibrous stone. [0, 1].
  double sheen = 0.0;
  std::uint32_t seed = 1;

  /// Throws OptionError when a value is out of range.
  void Check() const;
};

/// A material as two functions of the material coordinates (u, v), world units
/// along the surface: height along the surface normal and linear RGB albedo.
class Material {
 public:
  /// @param period_u, period_v  world units after which (u, v) wrap around a closed
  ///   surface (0: not periodic); feature sizes are stretched slightly so that a
  ///   whole number of features fits, and the material is seamless there.
  explicit Material(const MaterialOptions& options, double period_u = 0.0, double period_v = 0.0);

  /// Height in world units, within [-relief_height / 2, relief_height / 2].
  double Height(double u, double v) const;
  /// Height gradient (dh/du, dh/dv) by central differences at a quarter texel.
  Eigen::Vector2d HeightGradient(double u, double v) const;
  /// Linear RGB albedo in [0, 1], with low-frequency weathering stains (real
  /// surfaces have them, and they give SfM features to hold on to).
  Eigen::Vector3d Albedo(double u, double v) const;

  const MaterialOptions& options() const { return options_; }

 private:
  // Lattice cell size (world units) and period (cells) along one axis.
  struct Axis {
    double cell = 1.0;
    std::int64_t period = 0;
  };
  static Axis MakeAxis(double nominal_cell, double period_world, std::int64_t multiple = 1);
  Lattice MakeLattice(std::uint32_t salt, const Axis& x, const Axis& y) const;

  Eigen::Vector3d BaseAlbedo(double u, double v) const;
  double StoneHeight01(double u, double v) const;
  double BrickHeight01(double u, double v) const;
  double GrooveHeight01(double u, double v) const;

  MaterialOptions options_;
  double period_u_ = 0.0, period_v_ = 0.0;
  Axis cells_u_, cells_v_;      // stone cells, bricks, grooves (u only)
  Axis rough_u_, rough_v_;      // fine roughness
  Axis warp_u_, warp_v_;        // low-frequency variation
  Axis weather_u_, weather_v_;  // weathering stains on the albedo
};

/// A material sampled once on a texel grid over a rectangle of material
/// coordinates (wrapping where the surface is periodic), for fast shading: height
/// and albedo bilinearly interpolated, the gradient by central differences of the
/// grid. Geometry and shading of a rendering both read it, so they agree.
class BakedMaterial {
 public:
  /// @param u0, u1, v0, v1  material-coordinate rectangle, world units
  /// @param periodic_u, periodic_v  wrap instead of clamping at the rectangle's edges
  /// @param texel_size  grid spacing in world units (adjusted to divide a period)
  BakedMaterial(const Material& material, double u0, double u1, double v0, double v1,
                bool periodic_u, bool periodic_v, double texel_size);

  double Height(double u, double v) const;
  Eigen::Vector2d HeightGradient(double u, double v) const;
  Eigen::Vector3d Albedo(double u, double v) const;
  const MaterialOptions& options() const { return options_; }

 private:
  // Grid position of (u, v): base indices and fractions.
  void Locate(double u, double v, long& i0, long& j0, double& fu, double& fv) const;
  std::size_t Index(long i, long j) const;

  MaterialOptions options_;
  double u0_, v0_, du_, dv_;
  long nu_, nv_;
  bool periodic_u_, periodic_v_;
  std::vector<float> height_;
  std::vector<Eigen::Vector3f> albedo_;
};

/// An LRGB PTM of smooth random coefficients (seeded; each plane uniform in
/// [-0.3, 0.3] on a grid of side / 8, resized bicubically, plus 0.5 on the
/// constant term; white colour): a sample with structure a seam shows, for
/// tests and benchmarks of the quilting.
ptm::Ptm SmoothRandomPtm(int side, unsigned seed);

}  // namespace texlume::datasets
