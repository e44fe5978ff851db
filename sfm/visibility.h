#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.h"
#include "mesh/mesh.h"
#include "sfm/reconstruction.h"

namespace texlume::sfm {

/// Settings of ComputeVisibility.
struct VisibilityOptions {
  /// Largest side of the per-image depth buffer in pixels; 0 uses each photo's full
  /// resolution. Smaller buffers are faster but miss occluders thinner than a
  /// buffer pixel. Range: 0 or >= 16.
  int max_buffer_dimension = 0;
  /// A footprint pixel shows the triangle when the nearest surface there is no
  /// closer than the triangle's own depth times (1 - this). Range (0, 0.1].
  double depth_tolerance_relative = 1e-3;
  /// Points per edge, besides the corners, projected (with distortion, which
  /// bends edges) to test that the whole triangle lies inside the image. >= 0.
  int edge_samples = 3;
  /// Camera-frame depth (world units) below which a vertex counts as behind the
  /// camera. > 0.
  double near_depth = 1e-6;

  void Check() const;
};

/// How one triangle appears in one image.
struct TriangleView {
  ImageId image_id;
  /// The whole triangle is inside the image (after distortion), front-facing, and
  /// no part of it is hidden by any part of the mesh.
  bool fully_visible = false;
  /// Share of the triangle's projected area that is inside the image and not
  /// occluded, in [0, 1].
  float visible_fraction = 0.0f;
  /// Area of the projected triangle, in pixels of the photo.
  float projected_area_px = 0.0f;
  /// Angle between the face normal and the direction from the face centroid to
  /// the camera centre, in radians (0 = seen head-on).
  float angle_rad = 0.0f;
};

/// Where a triangle's best view came from.
enum class BestViewSource {
  kFullyVisible,      ///< paper 003 §3.0.1: smallest angle among fully visible views
  kPartiallyVisible,  ///< fallback: largest visible fraction, then smallest angle
  kNone,              ///< seen in no photo at all: synthesis uses neighbours only
};

/// Every view of one triangle and the one chosen for it.
struct TriangleVisibility {
  /// Views where the triangle is front-facing and at least partly visible,
  /// ordered by image id.
  std::vector<TriangleView> views;
  ImageId best_view;  ///< invalid when best_view_source == kNone
  BestViewSource best_view_source = BestViewSource::kNone;

  /// The images in which the triangle is fully visible (for multi-view use).
  std::vector<ImageId> FullyVisibleViews() const;
};

/// Visibility of every triangle in every image.
struct VisibilityResult {
  std::vector<TriangleVisibility> triangles;  ///< indexed by face
  std::size_t num_fully_seen = 0;             ///< triangles fully visible in >= 1 photo
  std::size_t num_partially_seen = 0;         ///< only partly visible in every photo that sees them
  std::size_t num_unseen = 0;                 ///< visible in no photo at all
  double seconds = 0.0;                       ///< wall time of the computation
};

/// Computes, for every (triangle, image), full visibility, visible fraction,
/// projected area and viewing angle, and picks each triangle's best view
/// (paper 003 §3.0.1, Algorithm 2 step 1; fallback for triangles fully visible
/// nowhere as in BestViewSource). Occlusion uses one z-buffer per image, built by
/// rasterising every mesh face (front and back facing) at the photo's distorted
/// projection, so partial occlusion of a triangle is detected, not only of its
/// corners. Images run in parallel (OpenMP). The mesh must be in the model's
/// world frame with outward-facing normals (mesh::LoadMesh makes closed meshes so).
VisibilityResult ComputeVisibility(const mesh::TriangleMesh& mesh,
                                   const Reconstruction& reconstruction,
                                   const VisibilityOptions& options = {},
                                   const ProgressCallback& progress = {});

}  // namespace texlume::sfm
