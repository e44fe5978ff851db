#include "sfm/camera_models.h"

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <stdexcept>

namespace texlume::sfm {
namespace {

struct ModelInfo {
  std::string_view name;
  int num_params;
  std::string_view params_info;
  bool single_focal;  // f, cx, cy ... instead of fx, fy, cx, cy ...
  bool fisheye;
};

constexpr std::array<ModelInfo, kNumCameraModels> kModels = {{
    {"SIMPLE_PINHOLE", 3, "f, cx, cy", true, false},
    {"PINHOLE", 4, "fx, fy, cx, cy", false, false},
    {"SIMPLE_RADIAL", 4, "f, cx, cy, k", true, false},
    {"RADIAL", 5, "f, cx, cy, k1, k2", true, false},
    {"OPENCV", 8, "fx, fy, cx, cy, k1, k2, p1, p2", false, false},
    {"OPENCV_FISHEYE", 8, "fx, fy, cx, cy, k1, k2, k3, k4", false, true},
    {"FULL_OPENCV", 12, "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6", false, false},
    {"FOV", 5, "fx, fy, cx, cy, omega", false, false},
    {"SIMPLE_RADIAL_FISHEYE", 4, "f, cx, cy, k", true, true},
    {"RADIAL_FISHEYE", 5, "f, cx, cy, k1, k2", true, true},
    {"THIN_PRISM_FISHEYE", 12, "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1", false, true},
}};

const ModelInfo& Info(CameraModelId model) {
  const int id = static_cast<int>(model);
  if (!IsValidCameraModelId(id)) {
    throw std::invalid_argument("unknown camera model id " + std::to_string(id));
  }
  return kModels[static_cast<std::size_t>(id)];
}

// Index of the first distortion parameter.
std::size_t ExtraOffset(CameraModelId model) { return Info(model).single_focal ? 3 : 4; }

// Fisheye models: the equidistant map from the normalised plane (radius r = tan theta)
// to the "angle plane" (radius theta).
Eigen::Vector2d AnglePlaneFromNormalized(const Eigen::Vector2d& u) {
  const double r = u.norm();
  if (r < 1e-15) return u;
  return u * (std::atan(r) / r);
}

// Distortion of the fisheye models, applied on the angle plane (radius theta).
Eigen::Vector2d FisheyeDistortAnglePlane(CameraModelId model, const double* k,
                                         const Eigen::Vector2d& a) {
  const double t2 = a.squaredNorm();
  switch (model) {
    case CameraModelId::kSimpleRadialFisheye:
      return a * (1.0 + k[0] * t2);
    case CameraModelId::kRadialFisheye:
      return a * (1.0 + k[0] * t2 + k[1] * t2 * t2);
    case CameraModelId::kOpenCVFisheye:
      return a * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
    case CameraModelId::kThinPrismFisheye: {
      // k = k1 k2 p1 p2 k3 k4 sx1 sy1: radial in theta^2, tangential and thin prism.
      const double radial = t2 * (k[0] + t2 * (k[1] + t2 * (k[4] + t2 * k[5])));
      const double x = a.x(), y = a.y();
      return {x + x * radial + 2.0 * k[2] * x * y + k[3] * (t2 + 2.0 * x * x) + k[6] * t2,
              y + y * radial + 2.0 * k[3] * x * y + k[2] * (t2 + 2.0 * y * y) + k[7] * t2};
    }
    default:
      return a;
  }
}

// FOV model (Devernay & Faugeras): r_d = atan(2 r tan(omega/2)) / omega.
Eigen::Vector2d FovDistort(double omega, const Eigen::Vector2d& u) {
  const double r2 = u.squaredNorm();
  const double omega2 = omega * omega;
  double factor;
  if (omega2 < 1e-8) {
    // Taylor expansion in omega: 1 + omega^2/12 - omega^2 r^2 / 3.
    factor = 1.0 + omega2 / 12.0 - omega2 * r2 / 3.0;
  } else {
    const double two_tan = 2.0 * std::tan(omega / 2.0);
    if (r2 < 1e-16) {
      // Taylor expansion in r: (2 tan(omega/2) / omega) (1 - (2 r tan(omega/2))^2 / 3).
      factor = two_tan / omega * (1.0 - two_tan * two_tan * r2 / 3.0);
    } else {
      const double r = std::sqrt(r2);
      factor = std::atan(r * two_tan) / (r * omega);
    }
  }
  return u * factor;
}

// Solves F(x) = target for x by Newton's method with a central-difference
// Jacobian, starting at `target`.
template <typename F>
Eigen::Vector2d SolveNewton(const F& forward, const Eigen::Vector2d& target) {
  Eigen::Vector2d x = target;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Eigen::Vector2d residual = forward(x) - target;
    if (residual.squaredNorm() < 1e-28) break;
    Eigen::Matrix2d jacobian;
    for (int c = 0; c < 2; ++c) {
      const double h = 1e-7 * std::max(1.0, std::abs(x[c]));
      Eigen::Vector2d xp = x, xm = x;
      xp[c] += h;
      xm[c] -= h;
      jacobian.col(c) = (forward(xp) - forward(xm)) / (2.0 * h);
    }
    const double det = jacobian.determinant();
    if (!std::isfinite(det) || std::abs(det) < 1e-300) break;
    const Eigen::Vector2d step = jacobian.inverse() * residual;
    x -= step;
    if (step.squaredNorm() < 1e-32) break;
  }
  return x;
}

}  // namespace

bool IsValidCameraModelId(int id) { return id >= 0 && id < kNumCameraModels; }

std::string_view CameraModelName(CameraModelId model) { return Info(model).name; }

std::optional<CameraModelId> CameraModelFromName(std::string_view name) {
  for (int id = 0; id < kNumCameraModels; ++id) {
    if (kModels[static_cast<std::size_t>(id)].name == name) return CameraModelId(id);
  }
  return std::nullopt;
}

int CameraModelNumParams(CameraModelId model) { return Info(model).num_params; }

std::string_view CameraModelParamsInfo(CameraModelId model) { return Info(model).params_info; }

bool IsFisheyeModel(CameraModelId model) { return Info(model).fisheye; }

Eigen::Vector2d DistortNormalized(CameraModelId model, std::span<const double> params,
                                  const Eigen::Vector2d& u) {
  const double* k = params.data() + ExtraOffset(model);
  const double x = u.x(), y = u.y();
  const double r2 = x * x + y * y;
  switch (model) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kPinhole:
      return u;
    case CameraModelId::kSimpleRadial:
      return u * (1.0 + k[0] * r2);
    case CameraModelId::kRadial:
      return u * (1.0 + k[0] * r2 + k[1] * r2 * r2);
    case CameraModelId::kOpenCV: {
      // k1 k2 p1 p2: radial plus tangential (Brown-Conrady).
      const double radial = k[0] * r2 + k[1] * r2 * r2;
      return {x + x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x),
              y + y * radial + 2.0 * k[3] * x * y + k[2] * (r2 + 2.0 * y * y)};
    }
    case CameraModelId::kFullOpenCV: {
      // k1 k2 p1 p2 k3 k4 k5 k6: rational radial model plus tangential.
      const double r4 = r2 * r2, r6 = r4 * r2;
      const double radial =
          (1.0 + k[0] * r2 + k[1] * r4 + k[4] * r6) / (1.0 + k[5] * r2 + k[6] * r4 + k[7] * r6);
      return {x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x),
              y * radial + 2.0 * k[3] * x * y + k[2] * (r2 + 2.0 * y * y)};
    }
    case CameraModelId::kFov:
      return FovDistort(k[0], u);
    case CameraModelId::kOpenCVFisheye:
    case CameraModelId::kSimpleRadialFisheye:
    case CameraModelId::kRadialFisheye:
    case CameraModelId::kThinPrismFisheye:
      return FisheyeDistortAnglePlane(model, k, AnglePlaneFromNormalized(u));
  }
  return u;
}

Camera Camera::Scaled(double factor) const {
  if (!(factor > 0.0) || !std::isfinite(factor))
    throw std::invalid_argument("camera scale factor must be positive");
  Camera c = *this;
  c.width = static_cast<std::uint64_t>(std::llround(static_cast<double>(width) * factor));
  c.height = static_cast<std::uint64_t>(std::llround(static_cast<double>(height) * factor));
  // Pixel corners map to pixel corners: (0, 0) stays, (w, h) becomes (f w, f h).
  const int scaled = Info(model).single_focal ? 3 : 4;
  for (int i = 0; i < scaled; ++i) c.params[static_cast<std::size_t>(i)] *= factor;
  return c;
}

Eigen::Vector2d Camera::FocalLength() const {
  return Info(model).single_focal ? Eigen::Vector2d(params[0], params[0])
                                  : Eigen::Vector2d(params[0], params[1]);
}

Eigen::Vector2d Camera::PrincipalPoint() const {
  return Info(model).single_focal ? Eigen::Vector2d(params[1], params[2])
                                  : Eigen::Vector2d(params[2], params[3]);
}

std::optional<Eigen::Vector2d> Camera::ImageFromCam(const Eigen::Vector3d& point_in_cam) const {
  if (!(point_in_cam.z() > 0.0)) return std::nullopt;
  const Eigen::Vector2d normalized = point_in_cam.head<2>() / point_in_cam.z();
  const Eigen::Vector2d distorted = DistortNormalized(model, params, normalized);
  return FocalLength().cwiseProduct(distorted) + PrincipalPoint();
}

Eigen::Vector3d Camera::CamRayFromImage(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d distorted = (pixel - PrincipalPoint()).cwiseQuotient(FocalLength());
  if (IsFisheyeModel(model)) {
    // Invert the distortion on the angle plane, then the equidistant map.
    const double* k = params.data() + ExtraOffset(model);
    const Eigen::Vector2d a = SolveNewton(
        [&](const Eigen::Vector2d& p) { return FisheyeDistortAnglePlane(model, k, p); }, distorted);
    const double theta = a.norm();
    if (theta < 1e-15) return Eigen::Vector3d(a.x(), a.y(), 1.0).normalized();
    const Eigen::Vector2d dir = a / theta;
    return Eigen::Vector3d(std::sin(theta) * dir.x(), std::sin(theta) * dir.y(), std::cos(theta));
  }
  const Eigen::Vector2d u = SolveNewton(
      [&](const Eigen::Vector2d& p) { return DistortNormalized(model, params, p); }, distorted);
  return Eigen::Vector3d(u.x(), u.y(), 1.0).normalized();
}

bool Camera::IsInImage(const Eigen::Vector2d& pixel) const {
  return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= static_cast<double>(width) &&
         pixel.y() <= static_cast<double>(height);
}

void Camera::Check() const {
  const int expected = CameraModelNumParams(model);
  if (static_cast<int>(params.size()) != expected) {
    throw std::invalid_argument(std::string(CameraModelName(model)) + " takes " +
                                std::to_string(expected) + " parameters, got " +
                                std::to_string(params.size()));
  }
  if (width == 0 || height == 0) throw std::invalid_argument("camera size is zero");
  for (double p : params) {
    if (!std::isfinite(p)) throw std::invalid_argument("camera parameter is not finite");
  }
  const Eigen::Vector2d f = FocalLength();
  if (!(f.x() > 0.0 && f.y() > 0.0)) {
    throw std::invalid_argument("focal length must be positive");
  }
}

}  // namespace texlume::sfm
