#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/progress.h"
#include "datasets_synthetic/material.h"
#include "datasets_synthetic/photo_sensor.h"
#include "datasets_synthetic/renderer.h"
#include "datasets_synthetic/shapes.h"
#include "ptm/ptm.h"
#include "sfm/camera_models.h"
#include "sfm/lights.h"

namespace texlume::datasets {

/// Settings of a complete synthetic heritage scene (docs/synthetic_scenes.md):
/// a material sample with its RTI and BTF captures and ground-truth maps, and an
/// object of that material photographed under known lights, with its COLMAP model.
struct SceneOptions {
  SceneShape shape = SceneShape::kSphere;
  MaterialOptions material;

  // Object photos.
  int num_images = 36;           ///< [3, 500]; 10-degree steps let COLMAP register them all
  int image_width = 640;         ///< pixels, [64, 8192]
  int image_height = 480;        ///< pixels, [64, 8192]
  double focal_px = 600.0;       ///< pixels
  double camera_distance = 3.5;  ///< world units from the origin
  sfm::CameraModelId camera_model = sfm::CameraModelId::kPinhole;  ///< PINHOLE or OPENCV
  int max_lights_per_image = 3;  ///< each photo has 1..this many directional lights, [1, 3]
  /// The photos' lights lie within this range of azimuths centred on their camera's,
  /// degrees, [0, 360] (72: the camera's side; 360: from anywhere around the object).
  double photo_light_azimuth_spread_deg = 72.0;
  /// Per-photo exposure drawn in [0.8, 1.2] (recorded in scene.json); off: 1 for all.
  bool vary_exposure = true;
  int num_held_out_views = 4;        ///< [0, 100]
  int held_out_lights_per_view = 3;  ///< [1, 20]
  /// Elevations (degrees above the horizontal plane) between which the held-out
  /// lights lie, on a dome turned towards each view. Low ones test grazing
  /// light: the relief's cast shadows, the PTM's horizon. [0, 90], min <= max.
  double held_out_min_elevation_deg = 25.0;
  double held_out_max_elevation_deg = 65.0;
  /// Held-out views are rendered at this many times the photos' resolution (the
  /// same camera, its size, focal length and principal point scaled), so models
  /// can be compared at full resolution and at the photos'. [1, 4]
  int held_out_scale = 1;
  /// The coarse mesh: 0 = the shape's standard one (CoarseMesh: 1280 triangles
  /// on the sphere); 1..7 as ObjectSceneOptions::resolution (the sphere's
  /// icosphere level: 20 * 4^N triangles).
  int mesh_resolution = 0;
  /// > 0: a coarse mesh of about this many faces instead (ShapeMeshWithFaces; up
  /// to ObjectSceneOptions::kMaxTargetFaces): a monument-scale scene.
  std::int64_t mesh_faces = 0;
  /// Rings the photos lie on (ObjectSceneOptions::camera_rings): 1 is the gently
  /// waving ring of the standard scenes; more, with a shorter camera distance and
  /// a longer focal length, is a monument's capture of close photos. [1, 20].
  int camera_rings = 1;

  // Material sample captures (orthographic, rectified to the material frame).
  int capture_size = 256;                ///< texels per side, [16, 4096]
  int num_capture_lights = 40;           ///< RTI dome, [6, 500]
  int num_held_out_capture_lights = 10;  ///< [0, 500]
  bool write_btf = true;
  /// Photos of an unseen planar surface of the material at half resolution under
  /// 3 lights, with full-resolution ground truth (for planar synthesis).
  bool write_surface = true;
  int btf_size = 128;        ///< texels per side, [16, 1024]
  int btf_view_count = 6;    ///< [1, 64]
  int btf_light_count = 12;  ///< [1, 128]

  /// Edge length of the displaced geometry's triangles, world units; 0 = 2 texels.
  double tessellation_step = 0.0;
  ShadingOptions shading;
  /// What the camera adds to the object photos (noise, vignetting, white
  /// balance, JPEG); off by default. The held-out truth stays clean.
  SensorOptions sensor;
  /// Error of the object photos' recorded light directions: each direction in
  /// lights.json is turned from the one that lit the photo by a random angle of
  /// this RMS, degrees (as a light-calibration sphere measures them). The
  /// held-out lights stay exact. 0 = exact. [0, 20].
  double light_error_deg = 0.0;
  std::uint32_t seed = 1;

  void Check() const;
};

/// Turns on what real captures have and the clean scenes leave out (issue 29),
/// at levels typical of a museum photo session: sensor noise of about one grey
/// level, JPEG quality 90, vignetting 0.2, white balance within 5 %, a specular
/// lobe (0.05, exponent 30) with sheen 0.1, one bounce of interreflection
/// (4 rays per sample) and light directions 2 degrees off. `texlume scene` uses
/// these by default; `--clean` gives the clean scene.
void UseRealisticCapture(SceneOptions& options);

/// The small object scene the tests and benches share: 12 photos of 320 x 240
/// (focal 300 px), a 128-texel material capture under 24 lights with texels of
/// 0.004 world units, no held-out capture lights, no BTF, no surface photos.
/// Callers set the rest (held-out views, relief, BTF).
SceneOptions SmallObjectSceneOptions(SceneShape shape, MaterialKind kind);

/// The sample PTM fitted (ptm::FitPtmFromFiles, default settings) to the
/// material capture of a scene GenerateScene wrote into `scene_dir`.
ptm::Ptm FitSceneSample(const std::filesystem::path& scene_dir);

/// Settings for a scene used only for its material outputs (captures, planar
/// surface): a plane object with 3 tiny photos, no BTF, no held-out views.
SceneOptions MaterialOnlySceneOptions(MaterialKind kind, int capture_size, int capture_lights);

/// What GenerateScene wrote.
struct SceneSummary {
  std::filesystem::path dir;
  std::size_t num_files = 0;
  std::size_t displaced_triangles = 0;  ///< of the object geometry
  double seconds_total = 0.0;
  std::vector<std::pair<std::string, double>> stage_seconds;
};

/// Directional lights on a dome: `count` directions in rings between the given
/// elevations (degrees), ring sizes proportional to cos(elevation); `offset`
/// in [0, 1) shifts azimuths and elevations by that share of a step, so a second
/// dome with offset 0.5 interleaves with the first (held-out lights).
/// Directions are in the material frame (x right, y up, z out of the surface).
std::vector<Eigen::Vector3d> DomeLights(int count, double min_elevation_deg,
                                        double max_elevation_deg, double offset);

/// Writes the complete scene folder (layout in docs/synthetic_scenes.md) into
/// `dir`. Deterministic: the same options give the same bytes.
SceneSummary GenerateScene(const SceneOptions& options, const std::filesystem::path& dir,
                           const ProgressCallback& progress = {});

/// Photos of a planar surface made of the material (issue 5, paper 003 Fig. 3):
/// a region of the material away from the captured sample, seen orthographically
/// from above at 1/scale of the sample's resolution under some lights, and the
/// same region at full resolution as ground truth.
struct PlanarSurfaceOptions {
  MaterialOptions material;
  int size = 256;  ///< texels of the surface per side (the PTM_out size)
  int scale = 2;   ///< texels per photo pixel, >= 1, divides size
  /// Where the region starts, in texels from the sample's origin (away from the
  /// RTI-captured area so the photos are of unseen surface).
  int offset = 512;
  ShadingOptions shading;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};
struct PlanarSurfaceRenders {
  /// 8-bit sRGB (OpenCV BGR order) photos, size/scale pixels per side, one per light.
  std::vector<cv::Mat> photos;
  /// 8-bit sRGB ground truth at full resolution, one per light given for it.
  std::vector<cv::Mat> truth;
};
PlanarSurfaceRenders RenderPlanarSurface(const PlanarSurfaceOptions& options,
                                         const std::vector<Eigen::Vector3d>& photo_lights,
                                         const std::vector<Eigen::Vector3d>& truth_lights);

/// Writes an image as PNG atomically (temporary name, then rename).
void WritePngAtomically(const std::filesystem::path& path, const cv::Mat& image);

/// The mask of a rendering: 255 where at least half of a pixel's samples hit.
cv::Mat CoverageMask(const Rendering& rendering);

}  // namespace texlume::datasets
