#include "render/view_pictures.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "core/image_io.h"
#include "mesh/mesh.h"
#include "render/metrics.h"

namespace texlume::render {
namespace {

// The reference divided by its exposure (linear domain), back to display values.
cv::Mat WithoutGain(const cv::Mat& rgb, double gain) {
  if (gain == 1.0) return rgb;
  cv::Mat out = rgb.clone();
  out.forEach<cv::Vec3f>([gain](cv::Vec3f& p, const int*) {
    for (int c = 0; c < 3; ++c)
      p[c] = LinearToSrgb(std::min(1.0f, static_cast<float>(SrgbToLinear(p[c]) / gain)));
  });
  return out;
}

sfm::Camera CameraAtWidth(const sfm::Camera& camera, int width) {
  const double factor =
      std::min(1.0, static_cast<double>(width) / static_cast<double>(camera.width));
  return factor < 1.0 ? camera.Scaled(factor) : camera;
}

// The reference at `size` over its gain, and its mask there (empty = none given).
void ReadReference(const PictureView& view, const cv::Size& size, ViewPictures& out) {
  const cv::Mat full = view.reference.empty() ? ReadPhotoRgb(view.reference_image) : view.reference;
  if (full.cols != static_cast<int>(view.camera.width) ||
      full.rows != static_cast<int>(view.camera.height))
    throw InputError(view.reference_image.string(), "does not match its camera's size");
  cv::resize(WithoutGain(full, view.reference_gain), out.reference, size, 0, 0, cv::INTER_AREA);
  if (view.reference_mask.empty()) return;
  const cv::Mat mask = ReadImageGrey(view.reference_mask) > 0.5f;
  if (mask.size() != full.size())
    throw InputError(view.reference_mask.string(), "does not match its image's size");
  cv::resize(mask, out.inside, size, 0, 0, cv::INTER_NEAREST);
  out.inside = out.inside > 127;
}

}  // namespace

ViewPictures DrawView(const ModelRenderer& renderer,
                      const std::vector<std::pair<std::string, RenderMode>>& modes,
                      const PictureView& view, int width) {
  const sfm::Camera camera = CameraAtWidth(view.camera, width);
  ViewPictures out;
  out.name = view.name;
  out.lights = view.lights;
  const bool has_reference = !view.reference_image.empty() || !view.reference.empty();
  if (has_reference)
    ReadReference(view, cv::Size(static_cast<int>(camera.width), static_cast<int>(camera.height)),
                  out);
  for (const auto& [name, mode] : modes) {
    const RenderedView r = renderer.Render(camera, view.cam_from_world, view.lights, mode, 2);
    ViewPictures::Drawn drawn{name, r.rgb};
    if (has_reference) {
      if (out.inside.empty()) out.inside = r.coverage > 0.5f;
      drawn.psnr = MaskedPsnr(r.rgb, out.reference, out.inside);
      drawn.ssim = MaskedSsim(r.rgb, out.reference, out.inside);
    }
    out.drawn.push_back(std::move(drawn));
  }
  out.world_per_pixel =
      WorldPerPixelAt(camera, view.cam_from_world, mesh::BoundingBoxCentre(renderer.model().mesh));
  return out;
}

double WorldPerPixelAt(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                       const Eigen::Vector3d& point_in_world) {
  const double depth = (cam_from_world * point_in_world).z();
  return depth > 0.0 ? depth / camera.FocalLength().mean() : 0.0;
}

std::vector<cv::Mat> DrawLightSweep(const ModelRenderer& renderer, const PictureView& view,
                                    int width, int frames, double elevation_deg) {
  const sfm::Camera camera =
      view.camera.Scaled(std::min(1.0, width / static_cast<double>(view.camera.width)));
  const Eigen::Matrix3d world_from_cam =
      view.cam_from_world.rotation.toRotationMatrix().transpose();
  const double el = elevation_deg * std::numbers::pi / 180.0;
  std::vector<cv::Mat> out;
  for (int k = 0; k < frames; ++k) {
    const double az = 2.0 * std::numbers::pi * k / frames;
    // Camera frame: x right, y down, z forward; the light on the viewer's side.
    const Eigen::Vector3d towards_light_in_cam(std::cos(el) * std::cos(az),
                                               -std::cos(el) * std::sin(az), -std::sin(el));
    sfm::ObjectLight light;
    light.direction_in_world = (world_from_cam * towards_light_in_cam).normalized();
    out.push_back(renderer.Render(camera, view.cam_from_world, {light}, RenderMode::kPtm, 2).rgb);
  }
  return out;
}

std::vector<std::pair<Eigen::Vector3d, cv::Mat>> RelightSample(const ptm::Ptm& sample, int width,
                                                               double elevation_deg) {
  std::vector<Eigen::Vector3d> lights = {Eigen::Vector3d::UnitZ()};
  const double el = elevation_deg * std::numbers::pi / 180.0;
  for (int k = 0; k < 4; ++k) {
    const double az = k * std::numbers::pi / 2.0;
    lights.emplace_back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  }
  std::vector<std::pair<Eigen::Vector3d, cv::Mat>> out;
  for (const Eigen::Vector3d& light : lights) {
    const std::vector<float> rgb = ptm::Relight(sample, light);
    const cv::Mat image(sample.height, sample.width, CV_32FC3, const_cast<float*>(rgb.data()));
    out.emplace_back(light, ResizedToWidth(image, width));
  }
  return out;
}

cv::Mat ResizedToWidth(const cv::Mat& image, int width) {
  if (image.cols <= width) return image.clone();
  const int height = std::max(
      1, static_cast<int>(std::lround(static_cast<double>(image.rows) * width / image.cols)));
  cv::Mat out;
  cv::resize(image, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return out;
}

std::vector<std::size_t> EvenlySpread(std::size_t n, int count) {
  std::vector<std::size_t> picked;
  const std::size_t k = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(0, count)));
  for (std::size_t i = 0; i < k; ++i) picked.push_back(i * n / k);
  return picked;
}

}  // namespace texlume::render
