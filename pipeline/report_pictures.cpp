#include "pipeline/report_pictures.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "core/check.h"
#include "core/errors.h"
#include "datasets_synthetic/object_scene.h"

namespace texlume::pipeline {

void ReportScene::Check() const {
  TEXLUME_CHECK(model != nullptr, "the report needs a model");
  if (picture_width < 32 || picture_width > 4096 || sweep_width < 32 || sweep_width > 4096)
    throw OptionError("report picture width must be in [32, 4096]");
  if (max_views < 0 || sweep_frames < 0 || sweep_frames > 64 || sample_width < 1)
    throw OptionError("report counts must be non-negative (sweep frames at most 64)");
}

void DrawReportPictures(const ReportScene& scene, report::ReportInputs& report,
                        const ProgressCallback& progress) {
  scene.Check();
  if (scene.sample) {
    report.sample_relit =
        render::RelightSample(*scene.sample, std::min(scene.sample_width, scene.sample->width),
                              scene.light_elevation_deg);
    report.sample_width = scene.sample->width;
    report.sample_height = scene.sample->height;
  }
  render::ModelRenderer renderer(*scene.model);
  renderer.flat_albedo = scene.flat_albedo;
  renderer.baked = scene.baked;
  std::vector<std::pair<std::string, render::RenderMode>> modes = {
      {"texlume", render::RenderMode::kPtm}, {"flat", render::RenderMode::kFlat}};
  if (!scene.baked.empty()) modes.emplace_back("baked", render::RenderMode::kBaked);
  const std::vector<std::size_t> picked = render::EvenlySpread(scene.views.size(), scene.max_views);
  report.views.clear();
  report.views_total = scene.views.size();
  const bool sweep = !picked.empty() && scene.sweep_frames > 0;
  const std::size_t steps = picked.size() + (sweep ? 1 : 0);
  for (std::size_t k = 0; k < picked.size(); ++k) {
    report.views.push_back(
        render::DrawView(renderer, modes, scene.views[picked[k]], scene.picture_width));
    if (progress) progress("report pictures", k + 1, steps);
  }
  if (!sweep) return;
  const render::PictureView& first = scene.views[picked.front()];
  report.sweep = render::DrawLightSweep(renderer, first, scene.sweep_width, scene.sweep_frames,
                                        scene.light_elevation_deg);
  report.sweep_view = first.name;
  report.sweep_elevation_deg = scene.light_elevation_deg;
  if (progress) progress("report pictures", steps, steps);
}

std::vector<render::PictureView> ViewsAroundMesh(const mesh::TriangleMesh& mesh, int count,
                                                 int width, int height) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Eigen::Vector3d& v : mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-9), distance = 3 * radius;
  sfm::Camera camera;
  camera.camera_id = sfm::CameraId(1);
  camera.model = sfm::CameraModelId::kPinhole;
  camera.width = static_cast<std::uint64_t>(width);
  camera.height = static_cast<std::uint64_t>(height);
  const double focal_px = 0.8 * 0.5 * height * distance / radius;
  camera.params = {focal_px, focal_px, width / 2.0, height / 2.0};
  const double elevation = 25 * std::numbers::pi / 180;
  std::vector<render::PictureView> views;
  for (int k = 0; k < count; ++k) {
    const double azimuth = 2 * std::numbers::pi * k / count;
    const Eigen::Vector3d toward_camera(std::cos(elevation) * std::cos(azimuth),
                                        std::cos(elevation) * std::sin(azimuth),
                                        std::sin(elevation));
    render::PictureView view;
    view.name = "view_" + std::to_string(k) + ".png";
    view.camera = camera;
    view.cam_from_world = datasets::LookAt(centre + distance * toward_camera, centre);
    const Eigen::Vector3d right =
        Eigen::Vector3d::UnitZ().cross(toward_camera).normalized();  // the camera's right
    sfm::ObjectLight light;
    light.direction_in_world =
        (toward_camera + 0.6 * Eigen::Vector3d::UnitZ() - 0.5 * right).normalized();
    view.lights = {light};
    views.push_back(std::move(view));
  }
  return views;
}

report::LightPlot LightPlotOfModel(const std::string& title,
                                   const std::vector<std::vector<sfm::ObjectLight>>& lights,
                                   const model::TexturedModel& model) {
  const Eigen::Vector3d centre = mesh::BoundingBoxCentre(model.mesh);
  const Eigen::Matrix3d hemisphere_from_world = model.orientation.HemisphereFromWorld();
  report::LightPlot plot{title,
                         "up as the photos were taken (estimated from the cameras), azimuth 0 "
                         "toward the side they were taken from",
                         {}};
  for (const auto& list : lights)
    for (const sfm::ObjectLight& l : list) {
      plot.directions.push_back(hemisphere_from_world * l.DirectionFrom(centre));
    }
  return plot;
}

report::LightPlot CaptureLightPlot(const std::vector<Eigen::Vector3d>& lights) {
  return {"the sample capture's lights",
          "the sample's frame: up out of the sample, azimuth 0 to "
          "its right (x), 90 degrees up its image (y)",
          lights};
}

}  // namespace texlume::pipeline
