#include "render/btf_shading.h"

#include <algorithm>
#include <cmath>

#include "ptm/coefficient_space.h"

namespace texlume::render {

Eigen::Vector3f ShadeBtf(const model::BtfModel& model, const ModelRenderer::SurfaceSample& s,
                         const std::vector<sfm::ObjectLight>& lights,
                         const ptm::LightResponse& response) {
  const cv::Mat& coords = model.sample_coords[static_cast<std::size_t>(s.atlas)];
  const int n = model.sample.Components();
  // Paper 004's lookup: the nearest texel's sample position, moved by the hit's
  // offset from that texel's centre turned into the sample frame (atlas and
  // sample texels have the same size); g Catmull-Rom in the sample. Across a seam
  // the nearest texel decides, so the cut stays sharp.
  const int nx = std::clamp(static_cast<int>(std::floor(s.atlas_px.x())), 0, coords.cols - 1);
  const int ny = std::clamp(static_cast<int>(std::floor(s.atlas_px.y())), 0, coords.rows - 1);
  const cv::Vec3f texel = coords.at<cv::Vec3f>(ny, nx);
  const double angle = texel[2];
  const double ca = std::cos(angle), sa = std::sin(angle);
  const double ox = s.atlas_px.x() - (nx + 0.5), oy = -(s.atlas_px.y() - (ny + 0.5));  // y up
  const Eigen::Vector2d sample_px(texel[0] + (ca * ox - sa * oy), texel[1] - (sa * ox + ca * oy));
  Eigen::VectorXf g(n);
  btf::SampleGeometry(model.sample, sample_px, g.data());
  auto to_sample = [&](const Eigen::Vector3d& world) {
    const Eigen::Vector3d d = s.frame.transpose() * world;
    return Eigen::Vector3d(ca * d.x() - sa * d.y(), sa * d.x() + ca * d.y(), d.z());
  };
  Eigen::Vector3d view = to_sample(s.to_viewer);
  if (view.z() < 0.02) {  // grazing (the smooth normal turns away): the horizon
    view.z() = 0.02;
    view.normalize();
  }
  std::vector<btf::MaterialLight> in_sample;
  in_sample.reserve(lights.size());
  for (const sfm::ObjectLight& light : lights)
    in_sample.emplace_back(to_sample(light.DirectionFrom(s.point)), light.intensity);
  const Eigen::Vector3f linear =
      btf::AppearanceUnder(model.sample, view, in_sample, response).transpose() * g;
  const cv::Vec3f k = model.colour_gain[static_cast<std::size_t>(s.atlas)].at<cv::Vec3f>(ny, nx);
  return {LinearToSrgb(linear[0] * k[0]), LinearToSrgb(linear[1] * k[1]),
          LinearToSrgb(linear[2] * k[2])};
}

RenderedView RenderBtf(const ModelRenderer& renderer, const model::BtfModel& btf,
                       const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                       const std::vector<sfm::ObjectLight>& lights, int samples_per_axis) {
  return renderer.RenderWith(camera, cam_from_world, samples_per_axis,
                             [&](const ModelRenderer::SurfaceSample& s) {
                               return ShadeBtf(btf, s, lights, renderer.model().light_response);
                             });
}

}  // namespace texlume::render
