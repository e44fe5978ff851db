#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sfm/camera_models.h"
#include "sfm/types.h"

namespace texlume::sfm {

/// A rigid transform target_from_source: x_in_target = rotation * x_in_source + translation.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& x_in_source) const {
    return rotation * x_in_source + translation;
  }
  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return {inv, -(inv * translation)};
  }
};

/// A 2D feature of an image, optionally observed 3D point.
struct Point2D {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< pixels, top-left corner convention
  Point3DId point3d_id;                          ///< invalid when the feature has no 3D point
};

/// One registered photo of the model.
struct Image {
  ImageId image_id;
  /// World to camera (COLMAP's qvec/tvec): x_in_cam = R * x_in_world + t.
  Rigid3d cam_from_world;
  CameraId camera_id;
  std::string name;  ///< path relative to the image folder, as COLMAP stores it
  std::vector<Point2D> points2d;

  /// Camera centre in the world frame: -R^T t.
  Eigen::Vector3d ProjectionCenter() const { return cam_from_world.Inverse().translation; }
  /// Number of 2D features that observe a 3D point.
  std::size_t NumPoints3D() const;
};

/// One observation of a 3D point: an image and the index of its 2D feature.
struct TrackElement {
  ImageId image_id;
  std::uint32_t point2d_idx = 0;
};

/// A sparse 3D point of the model.
struct Point3D {
  Point3DId point3d_id;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< world frame
  std::array<std::uint8_t, 3> rgb = {0, 0, 0};
  double error = -1.0;  ///< mean reprojection error in pixels; -1 when unknown
  std::vector<TrackElement> track;
};

/// A COLMAP sparse model. Ordered maps give deterministic iteration and output.
struct Reconstruction {
  std::map<CameraId, Camera> cameras;
  std::map<ImageId, Image> images;
  std::map<Point3DId, Point3D> points3d;

  /// Sum of the track lengths of all points.
  std::size_t NumObservations() const;
  /// Mean track length (0 without points).
  double MeanTrackLength() const;
  /// Mean number of observations per registered image (0 without images).
  double MeanObservationsPerImage() const;
  /// Mean of the per-point reprojection errors that are known (0 when none is).
  double MeanReprojectionError() const;

  /// Projects a world point into an image with its camera; nullopt if behind it.
  std::optional<Eigen::Vector2d> Project(const Image& image,
                                         const Eigen::Vector3d& point_in_world) const;
};

}  // namespace texlume::sfm
