#include "render/model_render.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "core/check.h"
#include "core/cubic_interpolation.h"
#include "core/errors.h"
#include "mesh/ray_caster.h"
#include "synth/face_order.h"

namespace texlume::render {
namespace {

// Bilinear lookup of `count` floats per texel at atlas pixel position (x, y)
// (pixel centres at +0.5), clamped to the image.
template <typename Get>
void Bilinear(int width, int height, double x, double y, int count, const Get& get, float* out) {
  const double u = std::clamp(x - 0.5, 0.0, width - 1.0),
               v = std::clamp(y - 0.5, 0.0, height - 1.0);
  const int x0 = std::min(static_cast<int>(u), std::max(0, width - 2));
  const int y0 = std::min(static_cast<int>(v), std::max(0, height - 2));
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float fx = static_cast<float>(u - x0), fy = static_cast<float>(v - y0);
  for (int c = 0; c < count; ++c) {
    out[c] = (1 - fy) * ((1 - fx) * get(x0, y0, c) + fx * get(x1, y0, c)) +
             fy * ((1 - fx) * get(x0, y1, c) + fx * get(x1, y1, c));
  }
}

// The light factor of the relief's self-shadowing (SelfShadowing::LightFactor) at an
// atlas position: the horizon at the light's azimuth read bilinearly, as the atlas is.
double ShadowFactor(const ptm::SelfShadowing& shadowing, const Eigen::Vector2d& atlas_px,
                    const Eigen::Vector3d& light_in_texel_frame) {
  const ptm::HorizonMap& h = shadowing.horizon;
  const Eigen::Vector3d l = light_in_texel_frame.normalized();
  const double azimuth = std::atan2(l.y(), l.x());
  float horizon = 0.0f;
  Bilinear(
      h.width, h.height, atlas_px.x(), atlas_px.y(), 1,
      [&](int xx, int yy, int) {
        return static_cast<float>(
            h.ElevationAt(static_cast<std::size_t>(yy) * h.width + xx, azimuth));
      },
      &horizon);
  return shadowing.LightFactorAt(ptm::VisibilityAboveHorizon(
      std::asin(std::clamp(l.z(), -1.0, 1.0)), horizon, shadowing.penumbra_rad));
}

// A photo's gain times its white balance (when given), per channel.
std::array<double, 3> ChannelGains(const std::vector<double>& gains,
                                   const std::vector<std::array<double, 3>>& white_balance,
                                   std::size_t photo) {
  std::array<double, 3> g{gains[photo], gains[photo], gains[photo]};
  if (photo < white_balance.size())
    for (std::size_t c = 0; c < 3; ++c) g[c] *= white_balance[photo][c];
  return g;
}

Eigen::Vector2d ToOpenCv(const Eigen::Vector2d& colmap_px) {
  return colmap_px - Eigen::Vector2d(0.5, 0.5);
}

}  // namespace

struct ModelRenderer::Impl {
  std::unique_ptr<mesh::RayCaster> caster;
};

const char* RenderModeName(RenderMode mode) {
  switch (mode) {
    case RenderMode::kPtm:
      return "ptm";
    case RenderMode::kFlat:
      return "flat";
    case RenderMode::kBaked:
      return "baked";
  }
  return "ptm";
}

ModelRenderer::ModelRenderer(const model::TexturedModel& model) : model_(model), impl_(new Impl) {
  const mesh::TriangleMesh& mesh = model.mesh;
  vertex_normals_ = mesh::VertexNormals(mesh);
  TEXLUME_CHECK(model_.shadowing.empty() || model_.shadowing.size() == model_.atlases.size(),
                "no horizon maps, or one per atlas");
  face_frames_.resize(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    face_frames_[f] = model::AtlasFaceFrame(model, f);
  impl_->caster = mesh::RayCasterOf(mesh);
}

ModelRenderer::~ModelRenderer() = default;

RenderedView ModelRenderer::RenderWith(const sfm::Camera& camera,
                                       const sfm::Rigid3d& cam_from_world, int samples_per_axis,
                                       const Shader& shade) const {
  if (samples_per_axis < 1 || samples_per_axis > 8)
    throw OptionError("samples per axis must be in [1, 8]");
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  RenderedView out;
  out.rgb = cv::Mat(height, width, CV_32FC3, cv::Scalar::all(0));
  out.coverage = cv::Mat(height, width, CV_32FC1, cv::Scalar::all(0));
  const sfm::Rigid3d world_from_cam = cam_from_world.Inverse();
  const Eigen::Vector3d origin = world_from_cam.translation;
  const int n = samples_per_axis;
  const mesh::TriangleMesh& mesh = model_.mesh;

#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int hits = 0;
      for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
          const Eigen::Vector2d pixel(x + (sx + 0.5) / n, y + (sy + 0.5) / n);  // COLMAP pixels
          const Eigen::Vector3d direction = world_from_cam.rotation * camera.CamRayFromImage(pixel);
          const std::optional<mesh::RayCaster::Hit> hit =
              impl_->caster->Intersect(origin, direction);
          if (!hit) continue;
          ++hits;
          SurfaceSample s;
          s.face = hit->triangle;
          const double b1 = hit->b1, b2 = hit->b2, b0 = 1.0 - b1 - b2;
          s.point = origin + hit->distance * direction;
          s.to_viewer = (origin - s.point).normalized();
          s.smooth_normal =
              mesh::SmoothNormalAt(mesh, vertex_normals_, s.face, Eigen::Vector3d(b0, b1, b2));
          if (!model_.corner_px.empty()) {
            const auto& c = model_.corner_px[s.face];
            s.atlas = model_.face_atlas[s.face];
            s.atlas_px =
                b0 * c[0].cast<double>() + b1 * c[1].cast<double>() + b2 * c[2].cast<double>();
          }
          // The face frame turned by the smallest rotation that takes the face
          // normal to the interpolated vertex normal, so shading varies smoothly
          // across faces of the coarse mesh, as on the surface it approximates.
          s.frame = Eigen::Quaterniond::FromTwoVectors(face_frames_[s.face].col(2), s.smooth_normal)
                        .toRotationMatrix() *
                    face_frames_[s.face];
          sum += shade(s);
        }
      }
      if (hits == 0) continue;
      // Background is black: average over all rays, as a camera would.
      const float inv = 1.0f / static_cast<float>(n * n);
      out.rgb.at<cv::Vec3f>(y, x) = cv::Vec3f(sum.x() * inv, sum.y() * inv, sum.z() * inv);
      out.coverage.at<float>(y, x) = hits * inv;
    }
  }
  return out;
}

RenderedView ModelRenderer::Render(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                                   const std::vector<sfm::ObjectLight>& lights, RenderMode mode,
                                   int samples_per_axis) const {
  if (mode == RenderMode::kBaked && baked.size() != model_.atlases.size())
    throw OptionError("the baked baseline needs one baked texture per atlas");
  const Eigen::Vector3f flat_linear(SrgbToLinear(flat_albedo.x()), SrgbToLinear(flat_albedo.y()),
                                    SrgbToLinear(flat_albedo.z()));
  return RenderWith(camera, cam_from_world, samples_per_axis, [&](const SurfaceSample& s) {
    Eigen::Vector3f value = Eigen::Vector3f::Zero();
    std::array<float, 21> texel{};
    if (mode == RenderMode::kFlat) {
      double shading = 0.0;
      for (const sfm::ObjectLight& l : lights)
        shading += l.intensity * std::max(0.0, s.smooth_normal.dot(l.DirectionFrom(s.point)));
      for (int c = 0; c < 3; ++c)
        value[c] = LinearToSrgb(static_cast<float>(shading) * flat_linear[c]);
    } else if (mode == RenderMode::kBaked) {
      const cv::Mat& tex = baked[static_cast<std::size_t>(s.atlas)];
      Bilinear(
          tex.cols, tex.rows, s.atlas_px.x(), s.atlas_px.y(), 3,
          [&](int xx, int yy, int ch) { return tex.at<cv::Vec3f>(yy, xx)[ch]; }, texel.data());
      value = Eigen::Vector3f(texel[0], texel[1], texel[2]);
    } else {
      const ptm::Ptm& atlas = model_.atlases[static_cast<std::size_t>(s.atlas)];
      const int coefficient_count = atlas.NumPolynomials() * 6;
      const bool lrgb = atlas.format == ptm::PtmFormat::kLrgb;
      // Catmull-Rom, as the viewer reads the planes: bilinear reads flatten the
      // finest detail the atlas holds (issue 29).
      CatmullRomTaps(atlas.width, atlas.height, s.atlas_px.x() - 0.5, s.atlas_px.y() - 0.5)
          .Read(
              coefficient_count + (lrgb ? 3 : 0),
              [&](int xx, int yy, int ch) {
                const std::size_t t = static_cast<std::size_t>(yy) * atlas.width + xx;
                return ch < coefficient_count
                           ? atlas.Coefficients(t)[ch]
                           : atlas.colour[t * 3 + static_cast<std::size_t>(ch - coefficient_count)];
              },
              texel.data());
      std::vector<std::pair<Eigen::Vector3d, double>> local;  // lights in the face frame
      for (const sfm::ObjectLight& l : lights) {
        const Eigen::Vector3d direction = s.frame.transpose() * l.DirectionFrom(s.point);
        const double shadow =
            model_.shadowing.empty()
                ? 1.0
                : ShadowFactor(model_.shadowing[static_cast<std::size_t>(s.atlas)], s.atlas_px,
                               direction);
        local.emplace_back(direction, l.intensity * shadow);
      }
      value = synth::RelightMixture(texel.data(), lrgb ? texel.data() + 6 : nullptr, atlas.format,
                                    local, 1.0, model_.light_response,
                                    s.frame.transpose() * s.to_viewer);
    }
    return value;
  });
}

namespace {

// An atlas texel of a face and where a photo sees it (OpenCV pixel centres).
struct PhotoTexel {
  int x = 0, y = 0;
  Eigen::Vector2d at;
};

// The atlas texels of face `f` (within 2 % of its barycentric range) that a photo
// of `photo_size` taken by `camera` at `cam_from_world` sees, in texel order.
std::vector<PhotoTexel> FaceTexelsInPhoto(const model::TexturedModel& model, std::size_t f,
                                          const sfm::Camera& camera,
                                          const sfm::Rigid3d& cam_from_world, cv::Size photo_size,
                                          cv::Size atlas_size) {
  std::vector<PhotoTexel> texels;
  const mesh::TriangleMesh& mesh = model.mesh;
  const auto& c = model.corner_px[f];
  Eigen::Vector2f lo = c[0], hi = c[0];
  for (const auto& p : c) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double det = (c[1] - c[0]).x() * (c[2] - c[0]).y() - (c[1] - c[0]).y() * (c[2] - c[0]).x();
  if (std::abs(det) < 1e-12) return texels;
  for (int y = std::max(0, static_cast<int>(std::floor(lo.y())));
       y <= std::min(atlas_size.height - 1, static_cast<int>(std::ceil(hi.y()))); ++y) {
    for (int x = std::max(0, static_cast<int>(std::floor(lo.x())));
         x <= std::min(atlas_size.width - 1, static_cast<int>(std::ceil(hi.x()))); ++x) {
      const Eigen::Vector2d q(x + 0.5, y + 0.5);
      const Eigen::Vector2d d = q - c[0].cast<double>();
      const double b1 = (d.x() * (c[2] - c[0]).y() - d.y() * (c[2] - c[0]).x()) / det;
      const double b2 = ((c[1] - c[0]).x() * d.y() - (c[1] - c[0]).y() * d.x()) / det;
      const double b0 = 1 - b1 - b2;
      const double eps = -0.02;
      if (b0 < eps || b1 < eps || b2 < eps) continue;
      const Eigen::Vector3d world =
          b0 * mesh.Corner(f, 0) + b1 * mesh.Corner(f, 1) + b2 * mesh.Corner(f, 2);
      const auto px =
          camera.ImageFromCam(cam_from_world.rotation * world + cam_from_world.translation);
      if (!px) continue;
      const Eigen::Vector2d o = ToOpenCv(*px);
      if (o.x() < -0.5 || o.y() < -0.5 || o.x() > photo_size.width - 0.5 ||
          o.y() > photo_size.height - 0.5)
        continue;
      texels.push_back({x, y, o});
    }
  }
  return texels;
}

}  // namespace

std::vector<cv::Mat> BakePhotoTextures(const model::TexturedModel& model,
                                       const sfm::Reconstruction& reconstruction,
                                       const sfm::VisibilityResult& visibility,
                                       const std::vector<synth::MeshPhoto>& photos,
                                       const std::vector<double>& photo_gains,
                                       const std::vector<std::array<double, 3>>& white_balance) {
  std::map<sfm::ImageId, std::size_t> photo_index;
  for (std::size_t i = 0; i < photos.size(); ++i) photo_index[photos[i].image_id] = i;
  std::vector<cv::Mat> textures, filled;
  for (const ptm::Ptm& atlas : model.atlases) {
    textures.push_back(cv::Mat(atlas.height, atlas.width, CV_32FC3, cv::Scalar::all(0)));
    filled.push_back(cv::Mat::zeros(atlas.height, atlas.width, CV_8UC1));
  }
  for (const std::size_t f : synth::FacesByPhoto(synth::KeyPhotoOfFaces(visibility, photos),
                                                 synth::PhotosHeldTogether(photos))) {
    const sfm::TriangleVisibility& tv = visibility.triangles[f];
    const auto it = tv.best_view_source == sfm::BestViewSource::kNone
                        ? photo_index.end()
                        : photo_index.find(tv.best_view);
    if (it == photo_index.end()) continue;
    const synth::MeshPhoto& photo = photos[it->second];
    const sfm::Image& image = reconstruction.images.at(photo.image_id);
    const std::size_t atlas = static_cast<std::size_t>(model.face_atlas[f]);
    const std::vector<PhotoTexel> texels =
        FaceTexelsInPhoto(model, f, reconstruction.cameras.at(image.camera_id),
                          image.cam_from_world, photo.pixels.size(), textures[atlas].size());
    if (texels.empty()) continue;
    // The photo's region the bilinear taps reach.
    Eigen::Vector2d lo = texels[0].at, hi = texels[0].at;
    for (const PhotoTexel& texel : texels) lo = lo.cwiseMin(texel.at), hi = hi.cwiseMax(texel.at);
    const cv::Size size = photo.pixels.size();
    const cv::Point from(std::max(0, static_cast<int>(std::floor(lo.x())) - 1),
                         std::max(0, static_cast<int>(std::floor(lo.y())) - 1));
    const cv::Point to(std::min(size.width, static_cast<int>(std::floor(hi.x())) + 3),
                       std::min(size.height, static_cast<int>(std::floor(hi.y())) + 3));
    const cv::Mat region = photo.pixels.Display(cv::Rect(from, to));
    const std::array<double, 3> gain = ChannelGains(photo_gains, white_balance, it->second);
    for (const PhotoTexel& texel : texels) {
      float rgb[3];
      Bilinear(
          size.width, size.height, texel.at.x() + 0.5, texel.at.y() + 0.5, 3,
          [&](int xx, int yy, int ch) {
            return region.at<cv::Vec3f>(yy - from.y, xx - from.x)[ch];
          },
          rgb);
      cv::Vec3f& out = textures[atlas].at<cv::Vec3f>(texel.y, texel.x);
      for (int ch = 0; ch < 3; ++ch)
        out[ch] = LinearToSrgb(
            static_cast<float>(SrgbToLinear(rgb[ch]) / gain[static_cast<std::size_t>(ch)]));
      filled[atlas].at<std::uint8_t>(texel.y, texel.x) = 255;
    }
  }
  // Unfilled texels: the mean of the filled ones, after a few dilation rings.
  for (std::size_t a = 0; a < textures.size(); ++a) {
    const cv::Scalar mean = cv::mean(textures[a], filled[a]);
    for (int ring = 0; ring < 4; ++ring) {
      cv::Mat grown;
      cv::dilate(filled[a], grown, cv::Mat());
      cv::Mat blurred, weight;
      cv::Mat masked_tex;
      textures[a].copyTo(masked_tex);
      cv::Mat mask_f;
      filled[a].convertTo(mask_f, CV_32FC1, 1 / 255.0);
      cv::boxFilter(masked_tex, blurred, -1, cv::Size(3, 3), cv::Point(-1, -1), false);
      cv::boxFilter(mask_f, weight, -1, cv::Size(3, 3), cv::Point(-1, -1), false);
      for (int y = 0; y < grown.rows; ++y)
        for (int x = 0; x < grown.cols; ++x)
          if (grown.at<std::uint8_t>(y, x) && !filled[a].at<std::uint8_t>(y, x) &&
              weight.at<float>(y, x) > 0)
            textures[a].at<cv::Vec3f>(y, x) = blurred.at<cv::Vec3f>(y, x) / weight.at<float>(y, x);
      filled[a] = grown;
    }
    for (int y = 0; y < filled[a].rows; ++y)
      for (int x = 0; x < filled[a].cols; ++x)
        if (!filled[a].at<std::uint8_t>(y, x))
          textures[a].at<cv::Vec3f>(y, x) =
              cv::Vec3f(static_cast<float>(mean[0]), static_cast<float>(mean[1]),
                        static_cast<float>(mean[2]));
  }
  return textures;
}

Eigen::Vector3f MeanAlbedoFromPhotos(const mesh::TriangleMesh& mesh,
                                     const sfm::Reconstruction& reconstruction,
                                     const sfm::VisibilityResult& visibility,
                                     const std::vector<synth::MeshPhoto>& photos,
                                     const std::vector<double>& photo_gains,
                                     const std::vector<std::array<double, 3>>& white_balance) {
  std::map<sfm::ImageId, std::size_t> photo_index;
  for (std::size_t i = 0; i < photos.size(); ++i) photo_index[photos[i].image_id] = i;
  const std::vector<Eigen::Vector3d> normals = mesh::FaceNormals(mesh);
  const std::vector<double> areas = mesh::FaceAreas(mesh);
  Eigen::Vector3d colour_sum = Eigen::Vector3d::Zero();
  double shading_sum = 0.0;
  for (const std::size_t f : synth::FacesByPhoto(synth::KeyPhotoOfFaces(visibility, photos),
                                                 synth::PhotosHeldTogether(photos))) {
    const sfm::TriangleVisibility& tv = visibility.triangles[f];
    if (tv.best_view_source != sfm::BestViewSource::kFullyVisible) continue;
    const auto it = photo_index.find(tv.best_view);
    if (it == photo_index.end()) continue;
    const synth::MeshPhoto& photo = photos[it->second];
    const sfm::Image& image = reconstruction.images.at(photo.image_id);
    const sfm::Camera& camera = reconstruction.cameras.at(image.camera_id);
    const Eigen::Vector3d centroid =
        (mesh.Corner(f, 0) + mesh.Corner(f, 1) + mesh.Corner(f, 2)) / 3.0;
    const auto px = camera.ImageFromCam(image.cam_from_world.rotation * centroid +
                                        image.cam_from_world.translation);
    if (!px) continue;
    const int x = static_cast<int>(px->x()), y = static_cast<int>(px->y());
    const cv::Size size = photo.pixels.size();
    if (x < 0 || y < 0 || x >= size.width || y >= size.height) continue;
    double shading = 0.0;
    for (const sfm::ObjectLight& l : photo.lights)
      shading += l.intensity * std::max(0.0, normals[f].dot(l.DirectionFrom(centroid)));
    if (shading < 0.2) continue;
    const cv::Vec3f rgb = photo.pixels.Display(cv::Rect(x, y, 1, 1)).at<cv::Vec3f>(0, 0);
    const std::array<double, 3> gain = ChannelGains(photo_gains, white_balance, it->second);
    for (int c = 0; c < 3; ++c)
      colour_sum[c] += areas[f] * SrgbToLinear(rgb[c]) / gain[static_cast<std::size_t>(c)];
    shading_sum += areas[f] * shading;
  }
  if (shading_sum <= 0) return Eigen::Vector3f::Constant(0.5f);
  Eigen::Vector3f out;
  for (int c = 0; c < 3; ++c)
    out[c] = LinearToSrgb(static_cast<float>(colour_sum[c] / shading_sum));
  return out;
}

}  // namespace texlume::render
