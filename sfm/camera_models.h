#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sfm/types.h"

namespace texlume::sfm {

/// The camera models of COLMAP 3.8, with COLMAP's numeric ids (the id is what a
/// cameras.bin file stores). Parameter order per model is COLMAP's; see
/// CameraModelParamsInfo().
enum class CameraModelId : int {
  kSimplePinhole = 0,        ///< f, cx, cy
  kPinhole = 1,              ///< fx, fy, cx, cy
  kSimpleRadial = 2,         ///< f, cx, cy, k
  kRadial = 3,               ///< f, cx, cy, k1, k2
  kOpenCV = 4,               ///< fx, fy, cx, cy, k1, k2, p1, p2
  kOpenCVFisheye = 5,        ///< fx, fy, cx, cy, k1, k2, k3, k4
  kFullOpenCV = 6,           ///< fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6
  kFov = 7,                  ///< fx, fy, cx, cy, omega
  kSimpleRadialFisheye = 8,  ///< f, cx, cy, k
  kRadialFisheye = 9,        ///< f, cx, cy, k1, k2
  kThinPrismFisheye = 10,    ///< fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1
};

/// Number of camera models (valid ids are 0 .. kNumCameraModels-1).
inline constexpr int kNumCameraModels = 11;

/// True when `id` is one of the ids above.
bool IsValidCameraModelId(int id);
/// COLMAP's name of the model ("PINHOLE", ...). Precondition: valid model.
std::string_view CameraModelName(CameraModelId model);
/// The model with this COLMAP name, or nullopt.
std::optional<CameraModelId> CameraModelFromName(std::string_view name);
/// Number of parameters the model takes.
int CameraModelNumParams(CameraModelId model);
/// Comma-separated parameter names, as COLMAP documents them.
std::string_view CameraModelParamsInfo(CameraModelId model);
/// True for the fisheye models (5, 8, 9, 10), whose distortion acts on the
/// angle between the ray and the optical axis.
bool IsFisheyeModel(CameraModelId model);

/// Applies the model's lens distortion to a point on the normalised image plane
/// (x/z, y/z of a point in the camera frame) and returns the distorted normalised
/// point, before the focal lengths and principal point are applied.
/// `params` holds the full parameter vector of the model.
Eigen::Vector2d DistortNormalized(CameraModelId model, std::span<const double> params,
                                  const Eigen::Vector2d& undistorted);

/// A COLMAP camera: intrinsics shared by one or more images.
/// Pixel convention (DESIGN.md): (0,0) is the top-left corner of the top-left
/// pixel, whose centre is (0.5, 0.5); COLMAP uses the same convention.
struct Camera {
  CameraId camera_id;
  CameraModelId model = CameraModelId::kPinhole;
  std::uint64_t width = 0;   ///< pixels
  std::uint64_t height = 0;  ///< pixels
  std::vector<double> params;

  /// Projects a point given in the camera frame (+Z forward) to pixel
  /// coordinates, with distortion. nullopt when the point is not in front of the
  /// camera (z <= 0), where no COLMAP model projects.
  std::optional<Eigen::Vector2d> ImageFromCam(const Eigen::Vector3d& point_in_cam) const;

  /// Unprojects a pixel to the unit bearing vector of its ray in the camera frame
  /// (undistortion by Newton's method, converged to 1e-14 on the normalised plane).
  /// Fisheye models may return rays at 90 degrees or more from the axis.
  Eigen::Vector3d CamRayFromImage(const Eigen::Vector2d& pixel) const;

  /// True when the pixel position lies inside [0, width] x [0, height].
  bool IsInImage(const Eigen::Vector2d& pixel) const;

  /// The same camera for images `factor` times larger along each axis: size,
  /// focal lengths and principal point scaled (distortion, on the normalised
  /// plane, unchanged). factor > 0.
  Camera Scaled(double factor) const;

  /// Focal lengths (fx, fy) in pixels and principal point (cx, cy) in pixels.
  Eigen::Vector2d FocalLength() const;
  Eigen::Vector2d PrincipalPoint() const;

  /// Throws std::invalid_argument when the parameter count does not match the
  /// model, a size is zero or a focal length is not positive and finite.
  void Check() const;
};

}  // namespace texlume::sfm
