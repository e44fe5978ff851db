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

/// Which way is up in a model's frame, and from which side the photos saw the object,
/// as the photos tell it. Both are unit vectors in the model's (world) frame.
struct ViewingOrientation {
  /// COLMAP's own convention when nothing better is known: its frame is the first
  /// camera's, y pointing down the image and z along the view.
  Eigen::Vector3d up = -Eigen::Vector3d::UnitY();
  Eigen::Vector3d front = -Eigen::Vector3d::UnitZ();  ///< orthogonal to `up`

  /// The frame of the photos' hemisphere, as rows in the world frame: x toward the
  /// photos' side (front, made orthogonal to up), y = up x front, z = up.
  Eigen::Matrix3d HemisphereFromWorld() const;
};

/// Up: photos are taken upright (landscape, little roll) whatever the frame SfM chose,
/// so their x axes are horizontal: up is the direction most orthogonal to all of them
/// (the least eigenvector of their scatter), on the side of the cameras' mean up (each
/// camera's -y). When the x axes are nearly parallel (under about 6 degrees RMS apart),
/// the mean up made orthogonal to them.
/// Front: from `centre` toward the mean of the cameras' directions from it, made
/// orthogonal to up; toward the first image (lowest id) when the cameras surround the
/// object so that their mean is short (under half a unit vector's length). The
/// defaults of ViewingOrientation when the model has no images or up is undefined.
ViewingOrientation OrientationFromCameras(const Reconstruction& reconstruction,
                                          const Eigen::Vector3d& centre);

}  // namespace texlume::sfm
