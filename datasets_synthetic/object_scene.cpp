#include "datasets_synthetic/object_scene.h"

#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "sfm/colmap_io.h"
#include "sfm/errors.h"
#include "sfm/visibility.h"

namespace texlume::datasets {
namespace {

constexpr double kPi = std::numbers::pi;

}  // namespace

void ObjectSceneOptions::Check() const {
  if (resolution < 0 || resolution > 7) throw OptionError("resolution must be in [0, 7]");
  if (num_images < 1 || num_images > 1000) throw OptionError("num_images must be in [1, 1000]");
  if (image_width < 16 || image_width > 16384 || image_height < 16 || image_height > 16384) {
    throw OptionError("image size must be in [16, 16384]");
  }
  if (!(focal_px > 0.0)) throw OptionError("focal_px must be positive");
  if (!(camera_distance > 1.5)) throw OptionError("camera_distance must be > 1.5");
  if (num_points < 0) throw OptionError("num_points must be >= 0");
  if (!(observation_noise_px >= 0.0)) throw OptionError("observation_noise_px must be >= 0");
  if (camera_model != sfm::CameraModelId::kPinhole && camera_model != sfm::CameraModelId::kOpenCV) {
    throw OptionError("camera_model must be PINHOLE or OPENCV");
  }
}

sfm::TriangleMesh MakeIcosphere(int subdivisions, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  sfm::TriangleMesh mesh;
  mesh.vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                   {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  mesh.faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& v : mesh.vertices) v.normalize();
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      mesh.vertices.push_back(
          (mesh.vertices[static_cast<std::size_t>(a)] + mesh.vertices[static_cast<std::size_t>(b)])
              .normalized());
      const int index = static_cast<int>(mesh.vertices.size()) - 1;
      midpoint[key] = index;
      return index;
    };
    std::vector<std::array<int, 3>> faces;
    for (const auto& f : mesh.faces) {
      const int a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      faces.push_back({f[0], a, c});
      faces.push_back({f[1], b, a});
      faces.push_back({f[2], c, b});
      faces.push_back({a, b, c});
    }
    mesh.faces = std::move(faces);
  }
  for (auto& v : mesh.vertices) v *= radius;
  return mesh;
}

sfm::TriangleMesh MakeCylinder(int around, int along, double radius, double height) {
  sfm::TriangleMesh mesh;
  for (int j = 0; j <= along; ++j) {
    const double z = -height / 2 + height * j / along;
    for (int i = 0; i < around; ++i) {
      const double a = 2 * kPi * i / around;
      mesh.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), z);
    }
  }
  auto ring = [&](int i, int j) { return j * around + (i % around); };
  for (int j = 0; j < along; ++j) {
    for (int i = 0; i < around; ++i) {
      mesh.faces.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      mesh.faces.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0, 0, -height / 2);
  const int top = bottom + 1;
  mesh.vertices.emplace_back(0, 0, height / 2);
  for (int i = 0; i < around; ++i) {
    mesh.faces.push_back({bottom, ring(i + 1, 0), ring(i, 0)});
    mesh.faces.push_back({top, ring(i, along), ring(i + 1, along)});
  }
  return mesh;
}

sfm::TriangleMesh MakeGridPlane(int segments, double size) {
  sfm::TriangleMesh mesh;
  for (int j = 0; j <= segments; ++j) {
    for (int i = 0; i <= segments; ++i) {
      mesh.vertices.emplace_back(-size / 2 + size * i / segments, -size / 2 + size * j / segments,
                                 0.0);
    }
  }
  auto at = [&](int i, int j) { return j * (segments + 1) + i; };
  for (int j = 0; j < segments; ++j) {
    for (int i = 0; i < segments; ++i) {
      mesh.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return mesh;
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
  switch (options.shape) {
    case SceneShape::kSphere:
      scene.mesh = MakeIcosphere(options.resolution, 1.0);
      break;
    case SceneShape::kCylinder:
      scene.mesh = MakeCylinder(8 * std::max(1, options.resolution),
                                4 * std::max(1, options.resolution), 0.6, 1.6);
      break;
    case SceneShape::kPlane:
      scene.mesh = MakeGridPlane(8 * std::max(1, options.resolution), 2.0);
      break;
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

  // Two rings of cameras (elevations +35 and +10 degrees; the plane is seen from
  // above only), each camera with a directional light from a random direction in
  // the camera's hemisphere, raised above the horizon.
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int i = 0; i < options.num_images; ++i) {
    const double azimuth = 2 * kPi * i / options.num_images;
    const double elevation =
        (options.shape == SceneShape::kPlane ? 55.0 : (i % 2 ? 10.0 : 35.0)) * kPi / 180.0;
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

    const double light_azimuth = azimuth + (uniform(rng) - 0.5) * kPi / 1.5;
    const double light_elevation = (20.0 + 50.0 * uniform(rng)) * kPi / 180.0;
    sfm::ObjectLight light;
    light.direction_in_world = Eigen::Vector3d(std::cos(light_elevation) * std::cos(light_azimuth),
                                               std::cos(light_elevation) * std::sin(light_azimuth),
                                               std::sin(light_elevation));
    scene.lights[image.name] = {light};
  }

  // Sparse points on the surface, observed where their face is fully visible.
  if (options.num_points > 0) {
    const auto areas = sfm::FaceAreas(scene.mesh);
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
        const Eigen::Vector2d observed = *projected + Eigen::Vector2d(noise(rng), noise(rng));
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
  sfm::SaveMesh(scene.mesh, dir / "mesh.ply");
  sfm::WriteObjectLightsFile(scene.lights, dir / "lights.json");
}

}  // namespace texlume::datasets
