#include "datasets_synthetic/material.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"

namespace texlume::datasets {
namespace {

double Smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

Eigen::Vector3d Mix(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) {
  return a + (b - a) * t;
}

// Nominal feature sizes in world units (scaled by feature_scale).
constexpr double kStoneCell = 0.06;
constexpr double kRoughCell = 0.012;
constexpr double kWarpCell = 0.25;
constexpr double kBrickLength = 0.24;
constexpr double kBrickCourse = 0.08;
constexpr double kMortar = 0.012;
constexpr double kGroovePeriod = 0.03;
constexpr double kWeatherCell = 0.12;

}  // namespace

std::string_view MaterialKindName(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::kStone:
      return "stone";
    case MaterialKind::kBrick:
      return "brick";
    case MaterialKind::kGrooves:
      return "grooves";
  }
  return "?";
}

std::optional<MaterialKind> MaterialKindFromName(std::string_view name) {
  for (auto k : {MaterialKind::kStone, MaterialKind::kBrick, MaterialKind::kGrooves}) {
    if (MaterialKindName(k) == name) return k;
  }
  return std::nullopt;
}

void MaterialOptions::Check() const {
  if (!(texel_size > 0.0 && texel_size <= 1.0)) throw OptionError("texel_size must be in (0, 1]");
  if (!(relief_height >= 0.0 && relief_height <= 1.0)) {
    throw OptionError("relief_height must be in [0, 1]");
  }
  if (!(feature_scale > 0.0 && feature_scale <= 100.0)) {
    throw OptionError("feature_scale must be in (0, 100]");
  }
  if (!(specular >= 0.0 && specular <= 1.0)) throw OptionError("specular must be in [0, 1]");
  if (!(albedo_scale >= 0.0 && albedo_scale <= 1.0)) {
    throw OptionError("albedo_scale must be in [0, 1]");
  }
  if (!(shininess >= 1.0 && shininess <= 10000.0)) {
    throw OptionError("shininess must be in [1, 10000]");
  }
  if (!(sheen >= 0.0 && sheen <= 1.0)) throw OptionError("sheen must be in [0, 1]");
}

Material::Axis Material::MakeAxis(double nominal_cell, double period_world, std::int64_t multiple) {
  Axis a;
  if (period_world > 0.0) {
    std::int64_t n = std::max<std::int64_t>(
        multiple,
        static_cast<std::int64_t>(std::llround(period_world / nominal_cell / multiple)) * multiple);
    a.cell = period_world / static_cast<double>(n);
    a.period = n;
  } else {
    a.cell = nominal_cell;
  }
  return a;
}

Lattice Material::MakeLattice(std::uint32_t salt, const Axis& x, const Axis& y) const {
  return Lattice{options_.seed * 7919u + salt, x.period, y.period};
}

Material::Material(const MaterialOptions& options, double period_u, double period_v)
    : options_(options), period_u_(period_u), period_v_(period_v) {
  options_.Check();
  const double s = options_.feature_scale;
  switch (options_.kind) {
    case MaterialKind::kStone:
      cells_u_ = MakeAxis(kStoneCell * s, period_u);
      cells_v_ = MakeAxis(kStoneCell * s, period_v);
      break;
    case MaterialKind::kBrick:
      cells_u_ = MakeAxis(kBrickLength * s, period_u);
      cells_v_ = MakeAxis(kBrickCourse * s, period_v, 2);  // running bond repeats every 2 courses
      break;
    case MaterialKind::kGrooves:
      cells_u_ = MakeAxis(kGroovePeriod * s, period_u);
      cells_v_ = MakeAxis(kGroovePeriod * s, period_v);
      break;
  }
  rough_u_ = MakeAxis(kRoughCell * s, period_u);
  rough_v_ = MakeAxis(kRoughCell * s, period_v);
  warp_u_ = MakeAxis(kWarpCell * s, period_u);
  warp_v_ = MakeAxis(kWarpCell * s * 2.5, period_v);
  weather_u_ = MakeAxis(kWeatherCell * s, period_u);
  weather_v_ = MakeAxis(kWeatherCell * s, period_v);
}

double Material::StoneHeight01(double u, double v) const {
  const CellularSample c =
      Cellular(MakeLattice(1, cells_u_, cells_v_), u / cells_u_.cell, v / cells_v_.cell);
  const double crack = Smoothstep(0.0, 0.12, c.f2 - c.f1);  // 0 in the joints between stones
  const double dome = std::clamp(1.0 - c.f1, 0.0, 1.0);
  const double rough =
      FractalNoise(MakeLattice(2, rough_u_, rough_v_), u / rough_u_.cell, v / rough_v_.cell, 4);
  return 0.45 * crack + 0.2 * dome * crack + 0.15 * c.cell_random + 0.2 * (0.5 + 0.5 * rough);
}

double Material::BrickHeight01(double u, double v) const {
  const double s = options_.feature_scale;
  const double length = cells_u_.cell, course = cells_v_.cell;
  const double mortar = kMortar * s;
  const double j = std::floor(v / course);
  const double offset = (static_cast<std::int64_t>(j) % 2 != 0) ? length / 2 : 0.0;
  const double i = std::floor((u - offset) / length);
  const double a = u - offset - i * length, b = v - j * course;
  const double d = std::min(std::min(a, length - a), std::min(b, course - b)) - mortar / 2;
  const double rough =
      FractalNoise(MakeLattice(2, rough_u_, rough_v_), u / rough_u_.cell, v / rough_v_.cell, 3);
  if (d < 0.0) return 0.1 + 0.08 * (0.5 + 0.5 * rough);  // mortar joint
  const double brick_random = MakeLattice(3, cells_u_, cells_v_)
                                  .Hash(static_cast<std::int64_t>(i), static_cast<std::int64_t>(j));
  const double bevel = Smoothstep(0.0, 0.5 * mortar, d);
  return 0.3 + 0.45 * bevel + 0.1 * brick_random + 0.15 * (0.5 + 0.5 * rough);
}

double Material::GrooveHeight01(double u, double v) const {
  const double warp =
      0.35 * FractalNoise(MakeLattice(4, warp_u_, warp_v_), u / warp_u_.cell, v / warp_v_.cell, 2);
  const double phase = u / cells_u_.cell + 1.5 * warp;  // wavy grain, seamless when periodic
  const double t = phase - std::floor(phase);
  const double ridge = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * t);
  const double rough =
      FractalNoise(MakeLattice(2, rough_u_, rough_v_), u / rough_u_.cell, v / rough_v_.cell, 3);
  return 0.9 * std::pow(ridge, 0.6) + 0.1 * (0.5 + 0.5 * rough);
}

double Material::Height(double u, double v) const {
  if (options_.relief_height == 0.0) return 0.0;
  double h01 = 0.0;
  switch (options_.kind) {
    case MaterialKind::kStone:
      h01 = StoneHeight01(u, v);
      break;
    case MaterialKind::kBrick:
      h01 = BrickHeight01(u, v);
      break;
    case MaterialKind::kGrooves:
      h01 = GrooveHeight01(u, v);
      break;
  }
  return options_.relief_height * (std::clamp(h01, 0.0, 1.0) - 0.5);
}

Eigen::Vector2d Material::HeightGradient(double u, double v) const {
  const double e = 0.25 * options_.texel_size;
  return {(Height(u + e, v) - Height(u - e, v)) / (2 * e),
          (Height(u, v + e) - Height(u, v - e)) / (2 * e)};
}

Eigen::Vector3d Material::Albedo(double u, double v) const {
  const double stain = FractalNoise(MakeLattice(7, weather_u_, weather_v_), u / weather_u_.cell,
                                    v / weather_v_.cell, 3);
  return (BaseAlbedo(u, v) * (options_.albedo_scale * (0.8 + 0.25 * stain)))
      .cwiseMax(0.0)
      .cwiseMin(1.0);
}

Eigen::Vector3d Material::BaseAlbedo(double u, double v) const {
  const double mottle =
      FractalNoise(MakeLattice(5, rough_u_, rough_v_), u / rough_u_.cell, v / rough_v_.cell, 3);
  switch (options_.kind) {
    case MaterialKind::kStone: {
      const CellularSample c =
          Cellular(MakeLattice(1, cells_u_, cells_v_), u / cells_u_.cell, v / cells_v_.cell);
      const double crack = Smoothstep(0.0, 0.12, c.f2 - c.f1);
      const Eigen::Vector3d base(0.60, 0.56, 0.50);
      const Eigen::Vector3d tint =
          Mix(Eigen::Vector3d(0.85, 0.9, 0.95), Eigen::Vector3d(1.1, 1.02, 0.9), c.cell_random2);
      return (base.cwiseProduct(tint) * (0.9 + 0.1 * mottle) * (0.6 + 0.4 * crack))
          .cwiseMax(0.0)
          .cwiseMin(1.0);
    }
    case MaterialKind::kBrick: {
      const double h = BrickHeight01(u, v);
      if (h < 0.2) return Eigen::Vector3d(0.68, 0.66, 0.60) * (0.92 + 0.08 * mottle);
      const double course = cells_v_.cell, length = cells_u_.cell;
      const double j = std::floor(v / course);
      const double offset = (static_cast<std::int64_t>(j) % 2 != 0) ? length / 2 : 0.0;
      const double i = std::floor((u - offset) / length);
      const double r = MakeLattice(6, cells_u_, cells_v_)
                           .Hash(static_cast<std::int64_t>(i), static_cast<std::int64_t>(j));
      return (Eigen::Vector3d(0.56, 0.27, 0.18) * (0.8 + 0.4 * r) * (0.9 + 0.1 * mottle))
          .cwiseMin(1.0);
    }
    case MaterialKind::kGrooves: {
      const double h = GrooveHeight01(u, v);
      return Mix(Eigen::Vector3d(0.32, 0.20, 0.11), Eigen::Vector3d(0.64, 0.47, 0.30), h) *
             (0.92 + 0.08 * mottle);
    }
  }
  return Eigen::Vector3d::Constant(0.5);
}

BakedMaterial::BakedMaterial(const Material& material, double u0, double u1, double v0, double v1,
                             bool periodic_u, bool periodic_v, double texel_size)
    : options_(material.options()),
      u0_(u0),
      v0_(v0),
      periodic_u_(periodic_u),
      periodic_v_(periodic_v) {
  nu_ = std::max(2L, std::lround((u1 - u0) / texel_size));
  nv_ = std::max(2L, std::lround((v1 - v0) / texel_size));
  du_ = (u1 - u0) / static_cast<double>(nu_);
  dv_ = (v1 - v0) / static_cast<double>(nv_);
  height_.resize(static_cast<std::size_t>(nu_ * nv_));
  albedo_.resize(height_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (long j = 0; j < nv_; ++j) {
    for (long i = 0; i < nu_; ++i) {
      const double u = u0_ + (static_cast<double>(i) + 0.5) * du_;
      const double v = v0_ + (static_cast<double>(j) + 0.5) * dv_;
      height_[Index(i, j)] = static_cast<float>(material.Height(u, v));
      albedo_[Index(i, j)] = material.Albedo(u, v).cast<float>();
    }
  }
}

std::size_t BakedMaterial::Index(long i, long j) const {
  i = periodic_u_ ? ((i % nu_) + nu_) % nu_ : std::clamp(i, 0L, nu_ - 1);
  j = periodic_v_ ? ((j % nv_) + nv_) % nv_ : std::clamp(j, 0L, nv_ - 1);
  return static_cast<std::size_t>(j * nu_ + i);
}

void BakedMaterial::Locate(double u, double v, long& i0, long& j0, double& fu, double& fv) const {
  const double x = (u - u0_) / du_ - 0.5, y = (v - v0_) / dv_ - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  i0 = static_cast<long>(fx);
  j0 = static_cast<long>(fy);
  fu = x - fx;
  fv = y - fy;
}

double BakedMaterial::Height(double u, double v) const {
  long i, j;
  double fu, fv;
  Locate(u, v, i, j, fu, fv);
  const double a = height_[Index(i, j)] * (1 - fu) + height_[Index(i + 1, j)] * fu;
  const double b = height_[Index(i, j + 1)] * (1 - fu) + height_[Index(i + 1, j + 1)] * fu;
  return a * (1 - fv) + b * fv;
}

Eigen::Vector2d BakedMaterial::HeightGradient(double u, double v) const {
  long i, j;
  double fu, fv;
  Locate(u, v, i, j, fu, fv);
  auto grad = [&](long a, long b) {
    return Eigen::Vector2d((height_[Index(a + 1, b)] - height_[Index(a - 1, b)]) / (2 * du_),
                           (height_[Index(a, b + 1)] - height_[Index(a, b - 1)]) / (2 * dv_));
  };
  return (grad(i, j) * (1 - fu) + grad(i + 1, j) * fu) * (1 - fv) +
         (grad(i, j + 1) * (1 - fu) + grad(i + 1, j + 1) * fu) * fv;
}

Eigen::Vector3d BakedMaterial::Albedo(double u, double v) const {
  long i, j;
  double fu, fv;
  Locate(u, v, i, j, fu, fv);
  const Eigen::Vector3f a = albedo_[Index(i, j)] * static_cast<float>(1 - fu) +
                            albedo_[Index(i + 1, j)] * static_cast<float>(fu);
  const Eigen::Vector3f b = albedo_[Index(i, j + 1)] * static_cast<float>(1 - fu) +
                            albedo_[Index(i + 1, j + 1)] * static_cast<float>(fu);
  return (a * static_cast<float>(1 - fv) + b * static_cast<float>(fv)).cast<double>();
}

ptm::Ptm SmoothRandomPtm(int side, unsigned seed) {
  ptm::Ptm p;
  p.Resize(ptm::PtmFormat::kLrgb, side, side);
  cv::RNG rng(seed);
  for (int m = 0; m < 6; ++m) {
    cv::Mat coarse(side / 8, side / 8, CV_32FC1), plane;
    rng.fill(coarse, cv::RNG::UNIFORM, -0.3, 0.3);
    cv::resize(coarse, plane, cv::Size(side, side), 0, 0, cv::INTER_CUBIC);
    for (int t = 0; t < side * side; ++t)
      p.Coefficients(static_cast<std::size_t>(t))[m] =
          plane.at<float>(t / side, t % side) + (m == 5 ? 0.5f : 0.0f);
  }
  std::fill(p.colour.begin(), p.colour.end(), 1.0f);
  return p;
}

}  // namespace texlume::datasets
