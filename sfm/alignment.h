#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>

#include "sfm/reconstruction.h"

namespace texlume::sfm {

/// A similarity reference_from_estimate: x_ref = scale * rotation * x_est + translation.
struct SimilarityAlignment {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  std::size_t num_matched = 0;          ///< images present in both models (by name)
  double rms_center_error = 0.0;        ///< camera centres after alignment, reference units
  double max_center_error = 0.0;        ///< reference units
  double max_rotation_error_deg = 0.0;  ///< camera orientations after alignment
};

/// Aligns the camera centres of `estimate` to those of `reference` (images matched
/// by name) with the least-squares similarity (Umeyama), and measures the
/// remaining centre and orientation errors. Useful to check an SfM run against
/// ground truth. Throws std::invalid_argument with fewer than 3 common images.
SimilarityAlignment AlignByCameraCenters(const Reconstruction& reference,
                                         const Reconstruction& estimate);

/// `estimate` moved into the reference frame by `a` (reference_from_estimate):
/// points map by x_ref = s R x_est + t; each camera keeps its intrinsics and
/// its view (cam_from_ref = s cam_from_est(x_est), which projects alike).
/// What a user has when a mesh in one frame meets an SfM model in another.
Reconstruction TransformedIntoReference(const Reconstruction& estimate,
                                        const SimilarityAlignment& a);

}  // namespace texlume::sfm
