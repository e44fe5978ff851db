#include "datasets_synthetic/object_scene.h"

#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "core/errors.h"
#include "sfm/colmap_io.h"
#include "sfm/visibility.h"

namespace texlume::datasets {
namespace {

struct CameraAngles {
  double azimuth = 0;    ///< radians
  double elevation = 0;  ///< radians
};

// One ring: the elevation waves gently around it (neighbours stay close, as in
// a real photo set, while the set covers a band of elevations). Several rings:
// CameraRingElevations, the photos shared out evenly, each ring's azimuths half
// a step from the ring below's.
std::vector<CameraAngles> PhotoAngles(const ObjectSceneOptions& options) {
  std::vector<CameraAngles> angles;
  const int n = options.num_images;
  if (options.camera_rings == 1) {
    double mid = 22.0, amplitude = 12.0;
    if (options.shape == SceneShape::kPlane) mid = 55.0, amplitude = 10.0;
    if (options.shape == SceneShape::kTorus) mid = 38.0, amplitude = 12.0;
    for (int i = 0; i < n; ++i) {
      const double azimuth = 2 * std::numbers::pi * i / n;
      angles.push_back(
          {azimuth, (mid + amplitude * std::sin(3.0 * azimuth)) * std::numbers::pi / 180.0});
    }
    return angles;
  }
  const std::vector<double> elevations = CameraRingElevations(options.shape, options.camera_rings);
  const int rings = options.camera_rings;
  for (int ring = 0; ring < rings; ++ring) {
    const int on_ring = n / rings + (ring < n % rings ? 1 : 0);
    const double offset = ring % 2 == 0 ? 0.0 : 0.5;
    for (int i = 0; i < on_ring; ++i) {
      angles.push_back({2 * std::numbers::pi * (i + offset) / on_ring,
                        elevations[static_cast<std::size_t>(ring)]});
    }
  }
  return angles;
}

}  // namespace

std::vector<double> CameraRingElevations(SceneShape shape, int rings) {
  double low = -40.0, high = 55.0;  // degrees
  if (shape == SceneShape::kPlane) low = 35.0, high = 75.0;
  if (shape == SceneShape::kTorus) low = 10.0, high = 70.0;
  std::vector<double> elevations;
  for (int ring = 0; ring < rings; ++ring) {
    const double t = rings == 1 ? 0.5 : static_cast<double>(ring) / (rings - 1);
    elevations.push_back((low + t * (high - low)) * std::numbers::pi / 180.0);
  }
  return elevations;
}

void ObjectSceneOptions::Check() const {
  if (resolution < 0 || resolution > 7) throw OptionError("resolution must be in [0, 7]");
  if (num_images < 1 || num_images > 1000) throw OptionError("num_images must be in [1, 1000]");
  if (target_faces < 0 || target_faces > kMaxTargetFaces) {
    throw OptionError("target_faces must be in [0, " + std::to_string(kMaxTargetFaces) + "]");
  }
  if (camera_rings < 1 || camera_rings > 20 || camera_rings > num_images) {
    throw OptionError("camera_rings must be in [1, 20] and at most num_images");
  }
  if (image_width < 16 || image_width > 16384 || image_height < 16 || image_height > 16384) {
    throw OptionError("image size must be in [16, 16384]");
  }
  if (!(focal_px > 0.0)) throw OptionError("focal_px must be positive");
  if (!(camera_distance > 1.5)) throw OptionError("camera_distance must be > 1.5");
  if (num_points < 0) throw OptionError("num_points must be >= 0");
  if (!(observation_noise_px >= 0.0)) throw OptionError("observation_noise_px must be >= 0");
  if (max_lights_per_image < 1 || max_lights_per_image > 3) {
    throw OptionError("max_lights_per_image must be in [1, 3]");
  }
  if (!(light_azimuth_spread_deg >= 0.0 && light_azimuth_spread_deg <= 360.0))
    throw OptionError("light_azimuth_spread_deg must be in [0, 360]");
  if (camera_model != sfm::CameraModelId::kPinhole && camera_model != sfm::CameraModelId::kOpenCV) {
    throw OptionError("camera_model must be PINHOLE or OPENCV");
  }
}

sfm::Rigid3d LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target,
                    const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - center).normalized();  // camera forward
  Eigen::Vector3d x = z.cross(up);                           // image right
  if (x.norm() < 1e-9) x = z.cross(Eigen::Vector3d::UnitY());
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);  // image down
  Eigen::Matrix3d rotation;
  rotation.row(0) = x;
  rotation.row(1) = y;
  rotation.row(2) = z;
  sfm::Rigid3d cam_from_world;
  cam_from_world.rotation = Eigen::Quaterniond(rotation).normalized();
  cam_from_world.translation = -(cam_from_world.rotation * center);
  return cam_from_world;
}

ObjectScene MakeObjectScene(const ObjectSceneOptions& options) {
  options.Check();
  ObjectScene scene;
  const int res = options.resolution;
  if (options.target_faces > 0) {
    scene.mesh = ShapeMeshWithFaces(options.shape, options.target_faces);
  } else if (res == 0) {
    scene.mesh = CoarseMesh(options.shape);
  } else {
    switch (options.shape) {
      case SceneShape::kSphere:
        scene.mesh = MakeIcosphere(res, 1.0);
        break;
      case SceneShape::kCylinder:
        scene.mesh = MakeCylinder(8 * res, 4 * res, 0.6, 1.6);
        break;
      case SceneShape::kPlane:
        scene.mesh = MakeGridPlane(8 * res, 2.0);
        break;
      case SceneShape::kTorus:
        scene.mesh = MakeTorus(16 * res, 8 * res, 0.8, 0.35);
        break;
    }
  }
  std::mt19937_64 rng(options.seed);

  sfm::Camera camera;
  camera.camera_id = sfm::CameraId(1);
  camera.model = options.camera_model;
  camera.width = static_cast<std::uint64_t>(options.image_width);
  camera.height = static_cast<std::uint64_t>(options.image_height);
  const double cx = options.image_width / 2.0, cy = options.image_height / 2.0;
  if (options.camera_model == sfm::CameraModelId::kPinhole) {
    camera.params = {options.focal_px, options.focal_px, cx, cy};
  } else {
    camera.params = {options.focal_px, options.focal_px, cx, cy, -0.05, 0.01, 0.0005, -0.0003};
  }
  scene.reconstruction.cameras[camera.camera_id] = camera;

  // Cameras looking at the origin (the plane is seen from above only, the torus
  // from higher up so its hole shows). Each photo gets 1 to
  // max_lights_per_image directional lights within light_azimuth_spread_deg of
  // azimuth around the camera's (by default its side of the object), 25 to 65
  // degrees above the horizon, with intensities summing to about 1.
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const std::vector<CameraAngles> photo_angles = PhotoAngles(options);
  for (int i = 0; i < options.num_images; ++i) {
    const auto [azimuth, elevation] = photo_angles[static_cast<std::size_t>(i)];
    const Eigen::Vector3d center =
        options.camera_distance * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                                  std::cos(elevation) * std::sin(azimuth),
                                                  std::sin(elevation));
    sfm::Image image;
    image.image_id = sfm::ImageId(static_cast<std::uint32_t>(i + 1));
    image.camera_id = camera.camera_id;
    char name[32];
    std::snprintf(name, sizeof(name), "image_%03d.png", i);
    image.name = name;
    image.cam_from_world = LookAt(center, Eigen::Vector3d::Zero());
    scene.reconstruction.images[image.image_id] = image;

    const int num_lights = 1 + static_cast<int>(uniform(rng) * options.max_lights_per_image);
    std::vector<sfm::ObjectLight> lights;
    for (int k = 0; k < num_lights; ++k) {
      // pi / (180 / 72) is pi / 2.5 exactly: the default gives the same bits as before.
      const double light_azimuth = azimuth + (uniform(rng) - 0.5) * std::numbers::pi /
                                                 (180.0 / options.light_azimuth_spread_deg);
      const double light_elevation = (25.0 + 40.0 * uniform(rng)) * std::numbers::pi / 180.0;
      sfm::ObjectLight light;
      light.direction_in_world = Eigen::Vector3d(
          std::cos(light_elevation) * std::cos(light_azimuth),
          std::cos(light_elevation) * std::sin(light_azimuth), std::sin(light_elevation));
      light.intensity = (0.85 + 0.3 * uniform(rng)) / num_lights;
      lights.push_back(light);
    }
    scene.lights[image.name] = lights;
  }

  // Sparse points on the surface, observed where their face is fully visible.
  if (options.num_points > 0) {
    const auto areas = mesh::FaceAreas(scene.mesh);
    std::discrete_distribution<std::size_t> pick_face(areas.begin(), areas.end());
    sfm::VisibilityOptions vis_options;
    vis_options.max_buffer_dimension = 256;
    const auto visibility = sfm::ComputeVisibility(scene.mesh, scene.reconstruction, vis_options);
    std::normal_distribution<double> noise(0.0, options.observation_noise_px);
    for (int p = 0; p < options.num_points; ++p) {
      const std::size_t f = pick_face(rng);
      double a = uniform(rng), b = uniform(rng);
      if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      sfm::Point3D point;
      point.point3d_id = sfm::Point3DId(static_cast<std::uint64_t>(p + 1));
      point.xyz = scene.mesh.Corner(f, 0) +
                  a * (scene.mesh.Corner(f, 1) - scene.mesh.Corner(f, 0)) +
                  b * (scene.mesh.Corner(f, 2) - scene.mesh.Corner(f, 0));
      point.rgb = {static_cast<std::uint8_t>(100 + p % 100), 120, 140};
      double error_sum = 0.0;
      for (const sfm::ImageId image_id : visibility.triangles[f].FullyVisibleViews()) {
        sfm::Image& image = scene.reconstruction.images.at(image_id);
        const auto projected = scene.reconstruction.Project(image, point.xyz);
        if (!projected) continue;
        // Drawn one at a time, y first (as GCC evaluated the two draws in one call, whose
        // order C++ leaves unspecified): the same model whichever compiler built texlume.
        const double noise_y = noise(rng), noise_x = noise(rng);
        const Eigen::Vector2d observed = *projected + Eigen::Vector2d(noise_x, noise_y);
        error_sum += (observed - *projected).norm();
        point.track.push_back({image_id, static_cast<std::uint32_t>(image.points2d.size())});
        image.points2d.push_back({observed, point.point3d_id});
      }
      if (point.track.size() < 2) {
        // COLMAP keeps only points seen twice or more: drop this one again.
        for (const auto& e : point.track)
          scene.reconstruction.images.at(e.image_id).points2d.back().point3d_id = sfm::Point3DId();
        continue;
      }
      point.error = error_sum / static_cast<double>(point.track.size());
      scene.reconstruction.points3d[point.point3d_id] = point;
    }
  }
  return scene;
}

void WriteObjectScene(const ObjectScene& scene, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  sfm::WriteModel(scene.reconstruction, dir / "sparse", sfm::ModelFormat::kBinary);
  sfm::WriteModel(scene.reconstruction, dir / "sparse_txt", sfm::ModelFormat::kText);
  mesh::SaveMesh(scene.mesh, dir / "mesh.ply");
  sfm::WriteObjectLightsFile(scene.lights, dir / "lights.json");
}

}  // namespace texlume::datasets
