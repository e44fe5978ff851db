#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"
#include "sfm/camera_models.h"
#include "sfm/lights.h"
#include "sfm/reconstruction.h"

namespace texlume::datasets {

/// Settings of MakeObjectScene. Defaults give a small scene in well under a second.
struct ObjectSceneOptions {
  SceneShape shape = SceneShape::kSphere;
  /// Mesh resolution: 0 takes the shape's standard coarse mesh (CoarseMesh);
  /// 1..7 an icosphere subdivision level (sphere) or segments / 8 around and
  /// along (cylinder, plane, torus).
  int resolution = 3;
  /// > 0: a coarse mesh of about this many faces instead (ShapeMeshWithFaces), up
  /// to kMaxTargetFaces: a monument-scale mesh.
  std::int64_t target_faces = 0;
  static constexpr std::int64_t kMaxTargetFaces = std::int64_t{1} << 23;
  /// Number of photos around the object. Range [1, 1000].
  int num_images = 16;
  /// 1: the photos on one ring whose elevation waves gently around the object.
  /// 2 or more: on this many rings of even elevation steps (CameraRingElevations),
  /// the photos shared out evenly, each ring's azimuths half a step from the
  /// ring below: the layout of a monument's capture, where close photos on rings
  /// at several heights cover the object between them. [1, 20], <= num_images.
  int camera_rings = 1;
  int image_width = 640;    ///< pixels, [16, 16384]
  int image_height = 480;   ///< pixels, [16, 16384]
  double focal_px = 600.0;  ///< pixels, > 0
  /// Distance of the cameras from the origin, world units (> 1.5: outside the object).
  double camera_distance = 3.5;
  /// PINHOLE, or OPENCV with a mild barrel distortion.
  sfm::CameraModelId camera_model = sfm::CameraModelId::kPinhole;
  /// Sparse points sampled on the surface and observed in the photos that see them.
  int num_points = 1500;
  /// Standard deviation of the noise added to the 2D observations, pixels, >= 0.
  double observation_noise_px = 0.3;
  /// Each photo is lit by 1 to this many directional lights (drawn per photo). [1, 3].
  int max_lights_per_image = 1;
  /// The lights' azimuths lie within this range centred on their camera's, degrees, [0, 360].
  double light_azimuth_spread_deg = 72.0;
  std::uint32_t seed = 1;

  void Check() const;
};

/// The elevations (radians) of `rings` >= 2 camera rings around a shape, in even
/// steps: from below to above the equator for the sphere and cylinder (a camera
/// looking at the origin then sees the lower, middle and upper parts), from above
/// for the plane (seen from its front only) and the torus.
std::vector<double> CameraRingElevations(SceneShape shape, int rings);

/// A synthetic object: its coarse mesh, a COLMAP model of its photos (cameras,
/// poses, sparse points with tracks) and one directional light per photo.
struct ObjectScene {
  mesh::TriangleMesh mesh;
  sfm::Reconstruction reconstruction;
  sfm::ObjectLights lights;
};

/// Builds the scene deterministically from the options (same seed, same scene).
ObjectScene MakeObjectScene(const ObjectSceneOptions& options);

/// Writes `dir/sparse` (COLMAP .bin), `dir/sparse_txt` (COLMAP .txt), `dir/mesh.ply`
/// and `dir/lights.json`.
void WriteObjectScene(const ObjectScene& scene, const std::filesystem::path& dir);

/// The cam_from_world pose of a camera at `center_in_world` looking at
/// `target_in_world` with world +Z up in the image (camera +Y down).
sfm::Rigid3d LookAt(const Eigen::Vector3d& center_in_world, const Eigen::Vector3d& target_in_world,
                    const Eigen::Vector3d& up_in_world = Eigen::Vector3d::UnitZ());

}  // namespace texlume::datasets
