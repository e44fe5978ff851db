#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "sfm/lights.h"

namespace texlume::ptm {

/// The outline of the reflective sphere in the photos, in pixels (pixel (0,0)'s
/// top-left corner is the origin, as everywhere in texlume).
struct SphereCircle {
  double center_x = 0.0;
  double center_y = 0.0;
  double radius = 0.0;
};

/// Settings of the highlight search.
struct HighlightOptions {
  /// Pixels at or above this fraction of the brightest value inside the sphere
  /// belong to the highlight (its intensity-weighted centroid is used). (0, 1].
  double threshold_fraction = 0.9;
  /// Only the inner part of the disk is searched (rim pixels mix with the
  /// background). (0, 1].
  double search_radius_fraction = 0.97;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// The highlight's centre in a grayscale float image, or nullopt when the sphere
/// has no highlight (light behind it).
std::optional<Eigen::Vector2d> FindHighlight(const cv::Mat& gray, const SphereCircle& circle,
                                             const HighlightOptions& options = {});

/// The light direction (image frame: x right, y up, z towards the camera) that
/// puts a mirror highlight at `highlight_px` on the sphere, for a distant camera
/// looking along -z: l = 2 (n.v) n - v with v = (0, 0, 1).
Eigen::Vector3d LightFromHighlight(const SphereCircle& circle, const Eigen::Vector2d& highlight_px);

/// Finds the sphere as the most prominent circle (Hough) in the mean of the
/// photos. Throws InputError when none is found (then give the circle).
SphereCircle DetectSphere(const std::vector<cv::Mat>& gray_images, const std::string& label);

/// Highlight RTI: the `.lp` entries of a set of photos with a glossy sphere in
/// view; `circle` detected when not given. Photos without a highlight are
/// skipped and named in `skipped`. Throws InputError naming unreadable files.
std::vector<sfm::LpEntry> LightsFromSphere(const std::vector<std::filesystem::path>& files,
                                           std::optional<SphereCircle> circle,
                                           const HighlightOptions& options,
                                           std::vector<std::string>* skipped = nullptr,
                                           SphereCircle* used_circle = nullptr);

}  // namespace texlume::ptm
