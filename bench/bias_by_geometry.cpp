// Where a relit model is too bright or too dark (issue 29): the linear luma of
// rendered views against their truth, binned by the shading geometry at each
// pixel, the angles of Oren and Nayar's model: the light's elevation above the
// surface's tangent plane, the view's angle from the normal, and the cosine of the
// difference of their azimuths about the normal (towards: the view on the light's
// side, > 0.5; across, within +-0.5; away, < -0.5). The surface is the coarse
// mesh, smooth-shaded as the renderer shades it, hit by each masked pixel's ray.
//
//   bias_by_geometry MESH CAMERAS LIGHTS_JSON TRUTH_DIR MASKS_DIR LABEL=DIR [LABEL=DIR ...]
//
// CAMERAS is the COLMAP model of the truth views (their size), LIGHTS_JSON their
// object lights (one light per view; views with more are skipped). Each DIR holds
// an image of every view's name. Per bin it prints the pixels, the truth's mean
// linear luma and each row's (sum over the bin / the truth's sum - 1) in %.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/image_io.h"
#include "mesh/mesh.h"
#include "mesh/ray_caster.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"

namespace fs = std::filesystem;
using namespace texlume;

namespace {

constexpr std::array<double, 5> kElevationEdgesDeg{0, 10, 20, 40, 90.001};
constexpr std::array<double, 5> kViewEdgesDeg{0, 30, 50, 70, 90.001};
constexpr std::array<const char*, 3> kAzimuthNames{"away", "across", "towards"};
constexpr std::size_t kMinPixels = 500;

int BinOf(double value, const std::array<double, 5>& edges) {
  for (int b = 0; b + 1 < static_cast<int>(edges.size()); ++b)
    if (value >= edges[static_cast<std::size_t>(b)] &&
        value < edges[static_cast<std::size_t>(b) + 1])
      return b;
  return -1;
}

// The angles of Oren and Nayar's model at a surface point (unit vectors).
struct ShadingGeometry {
  double light_elevation_deg, view_angle_deg, cos_azimuth;
};

ShadingGeometry GeometryAt(const Eigen::Vector3d& normal, const Eigen::Vector3d& to_light,
                           const Eigen::Vector3d& to_viewer) {
  const double deg = 180.0 / std::numbers::pi;
  const Eigen::Vector3d light_tangent = to_light - normal.dot(to_light) * normal;
  const Eigen::Vector3d view_tangent = to_viewer - normal.dot(to_viewer) * normal;
  const double norms = light_tangent.norm() * view_tangent.norm();
  return {std::asin(std::clamp(normal.dot(to_light), -1.0, 1.0)) * deg,
          std::acos(std::clamp(normal.dot(to_viewer), -1.0, 1.0)) * deg,
          norms > 1e-12 ? light_tangent.dot(view_tangent) / norms : 0.0};
}

double LinearLuma(const cv::Vec3f& rgb_display) {
  return 0.2126 * SrgbToLinear(rgb_display[0]) + 0.7152 * SrgbToLinear(rgb_display[1]) +
         0.0722 * SrgbToLinear(rgb_display[2]);
}

struct Bin {
  std::size_t pixels = 0;
  double truth = 0;
  std::vector<double> rows;
};

class GeometryBins {
 public:
  GeometryBins(const fs::path& mesh_file, std::vector<std::pair<std::string, fs::path>> rows)
      : mesh_(mesh::LoadMesh(mesh_file).mesh),
        vertex_normals_(mesh::VertexNormals(mesh_)),
        caster_(mesh::RayCasterOf(mesh_)),
        rows_(std::move(rows)) {}

  // Adds one view's masked pixels.
  void AddView(const sfm::Camera& camera, const sfm::Image& image, const sfm::ObjectLight& light,
               const fs::path& truth_dir, const fs::path& masks_dir) {
    const cv::Mat truth = ReadPhotoRgb(truth_dir / image.name);
    const cv::Mat mask = ReadImageGrey(masks_dir / image.name);
    if (truth.cols != static_cast<int>(camera.width) ||
        truth.rows != static_cast<int>(camera.height))
      throw InputError((truth_dir / image.name).string(), "its size is not its camera's");
    if (mask.size() != truth.size())
      throw InputError((masks_dir / image.name).string(), "its size is not its view's");
    std::vector<cv::Mat> rendered;
    for (const auto& [label, dir] : rows_) {
      rendered.push_back(ReadPhotoRgb(dir / image.name));
      if (rendered.back().size() != truth.size())
        throw InputError((dir / image.name).string(), "its size is not the truth's");
    }
    const Eigen::Vector3d centre = image.ProjectionCenter();
    const Eigen::Matrix3d world_from_cam =
        image.cam_from_world.rotation.inverse().toRotationMatrix();
    for (int y = 0; y < truth.rows; ++y)
      for (int x = 0; x < truth.cols; ++x) {
        if (!(mask.at<float>(y, x) > 0.5f)) continue;
        const Eigen::Vector3d ray =
            world_from_cam * camera.CamRayFromImage(Eigen::Vector2d(x + 0.5, y + 0.5));
        const auto hit = caster_->Intersect(centre, ray);
        if (!hit) continue;
        const Eigen::Vector3d normal = mesh::SmoothNormalAt(
            mesh_, vertex_normals_, hit->triangle, {1.0 - hit->b1 - hit->b2, hit->b1, hit->b2});
        const Eigen::Vector3d point = centre + hit->distance * ray;
        const ShadingGeometry g = GeometryAt(normal, light.DirectionFrom(point), -ray.normalized());
        const int e = BinOf(g.light_elevation_deg, kElevationEdgesDeg);
        const int v = BinOf(g.view_angle_deg, kViewEdgesDeg);
        if (e < 0 || v < 0) continue;
        const int a = g.cos_azimuth > 0.5 ? 2 : (g.cos_azimuth < -0.5 ? 0 : 1);
        Bin& bin = bins_[{a, e, v}];
        bin.rows.resize(rows_.size(), 0.0);
        ++bin.pixels;
        bin.truth += LinearLuma(truth.at<cv::Vec3f>(y, x));
        for (std::size_t r = 0; r < rows_.size(); ++r)
          bin.rows[r] += LinearLuma(rendered[r].at<cv::Vec3f>(y, x));
      }
  }

  void Print() const {
    std::printf("| azimuth | light elevation | view angle | pixels | truth |");
    for (const auto& row : rows_) std::printf(" %s |", row.first.c_str());
    std::printf("\n|---|---|---|---|---|");
    for (std::size_t r = 0; r < rows_.size(); ++r) std::printf("---|");
    std::printf("\n");
    for (const auto& [key, bin] : bins_) {
      if (bin.pixels < kMinPixels || !(bin.truth > 0.0)) continue;
      const auto [a, e, v] = key;
      std::printf("| %s | %.0f-%.0f | %.0f-%.0f | %zu | %.4f |", kAzimuthNames[a],
                  kElevationEdgesDeg[e], std::floor(kElevationEdgesDeg[e + 1]), kViewEdgesDeg[v],
                  std::floor(kViewEdgesDeg[v + 1]), bin.pixels, bin.truth / bin.pixels);
      for (double sum : bin.rows) std::printf(" %+.1f |", 100.0 * (sum / bin.truth - 1.0));
      std::printf("\n");
    }
  }

 private:
  mesh::TriangleMesh mesh_;
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::unique_ptr<mesh::RayCaster> caster_;
  std::vector<std::pair<std::string, fs::path>> rows_;
  std::map<std::array<int, 3>, Bin> bins_;  // by azimuth, elevation, view
};

int Run(int argc, char** argv) {
  if (argc < 7) {
    std::fprintf(stderr,
                 "usage: bias_by_geometry MESH CAMERAS LIGHTS_JSON TRUTH_DIR MASKS_DIR "
                 "LABEL=DIR [LABEL=DIR ...]\n");
    return 2;
  }
  std::vector<std::pair<std::string, fs::path>> rows;
  for (int i = 6; i < argc; ++i) {
    const std::string arg = argv[i];
    const std::size_t eq = arg.find('=');
    if (eq == std::string::npos) throw OptionError("expected LABEL=DIR, got '" + arg + "'");
    rows.emplace_back(arg.substr(0, eq), arg.substr(eq + 1));
  }
  GeometryBins bins(argv[1], rows);
  const sfm::Reconstruction model = sfm::ReadModel(argv[2]).reconstruction;
  const sfm::ObjectLights lights = sfm::ReadObjectLightsFile(argv[3]);
  int views = 0;
  for (const auto& [id, image] : model.images) {
    const auto light = lights.find(image.name);
    if (light == lights.end() || light->second.size() != 1) continue;
    bins.AddView(model.cameras.at(image.camera_id), image, light->second.front(), argv[4], argv[5]);
    ++views;
  }
  if (views == 0) throw InputError(argv[3], "no view of the model has exactly one light here");
  std::printf("%d views with one light each\n\n", views);
  bins.Print();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bias_by_geometry: %s\n", e.what());
    return 1;
  }
}
