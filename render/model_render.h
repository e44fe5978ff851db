#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "mesh/mesh.h"
#include "model/model_io.h"
#include "sfm/lights.h"
#include "sfm/reconstruction.h"
#include "sfm/visibility.h"
#include "synth/mesh_synthesis.h"

namespace texlume::render {

/// A rendered view: display-domain RGB and the share of each pixel covered by
/// the model.
struct RenderedView {
  cv::Mat rgb;       ///< CV_32FC3, RGB display domain in [0, 1], black background
  cv::Mat coverage;  ///< CV_32FC1 in [0, 1]
};

/// What a render shows (paper 003 §3.1 and the two baselines of DESIGN.md).
enum class RenderMode {
  kPtm,    ///< the PTM atlases, per-triangle light in the texture-coordinate frame
  kFlat,   ///< the coarse mesh, smooth normals, one mean albedo, Lambertian
  kBaked,  ///< the photos baked into an ordinary texture, shown as they are (unlit)
};

/// "ptm", "flat" or "baked", as settings files name the modes.
const char* RenderModeName(RenderMode mode);

/// Ray-casts a textured model (Embree) through COLMAP cameras, distortion
/// included: perspective-correct by construction (barycentrics of the hit),
/// nearest surface only, `samples_per_axis`^2 rays per pixel. PTM atlases are read
/// Catmull-Rom (core/cubic_interpolation.h, as the viewer reads them); horizon maps
/// and baked textures bilinearly.
class ModelRenderer {
 public:
  explicit ModelRenderer(const model::TexturedModel& model);
  ~ModelRenderer();
  ModelRenderer(const ModelRenderer&) = delete;
  ModelRenderer& operator=(const ModelRenderer&) = delete;

  /// kPtm needs the model's atlases; kFlat `flat_albedo` (display RGB); kBaked
  /// `baked` (one CV_32FC3 display RGB texture per atlas, same size).
  RenderedView Render(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                      const std::vector<sfm::ObjectLight>& lights, RenderMode mode,
                      int samples_per_axis = 2) const;

  Eigen::Vector3f flat_albedo = Eigen::Vector3f::Constant(0.5f);
  std::vector<cv::Mat> baked;

  /// One ray's hit, for a shader.
  struct SurfaceSample {
    std::size_t face = 0;
    int atlas = 0;
    Eigen::Vector2d atlas_px = Eigen::Vector2d::Zero();   ///< texture coordinates, atlas pixels
    Eigen::Vector3d point = Eigen::Vector3d::Zero();      ///< world
    Eigen::Vector3d to_viewer = Eigen::Vector3d::Zero();  ///< unit, world
    Eigen::Vector3d smooth_normal = Eigen::Vector3d::Zero();
    /// Columns in world coordinates: the atlas frame of the face (AtlasFaceFrame)
    /// turned so that z is the smooth normal.
    Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  };
  /// Display RGB of one ray's hit. Called concurrently.
  using Shader = std::function<Eigen::Vector3f(const SurfaceSample&)>;
  /// Ray-casts the model as Render does, colouring each hit with `shade`.
  RenderedView RenderWith(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                          int samples_per_axis, const Shader& shade) const;

  const model::TexturedModel& model() const { return model_; }

 private:
  struct Impl;
  const model::TexturedModel& model_;
  std::vector<Eigen::Matrix3d> face_frames_;  // columns: x = dP/du, y = dP/dv (v up), z = n
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::unique_ptr<Impl> impl_;
};

/// The photogrammetry baseline: every atlas texel inside a face takes the colour
/// of its surface point in the face's best view (bilinear, divided by the
/// photo's gain and white balance in the linear domain; `white_balance` per
/// photo, or empty for none); faces seen fully in no photo take the partial
/// best view, then the mean. Gutters dilated. One CV_32FC3 per atlas.
std::vector<cv::Mat> BakePhotoTextures(
    const model::TexturedModel& model, const sfm::Reconstruction& reconstruction,
    const sfm::VisibilityResult& visibility, const std::vector<synth::MeshPhoto>& photos,
    const std::vector<double>& photo_gains,
    const std::vector<std::array<double, 3>>& white_balance = {});

/// The mean albedo seen in the photos (display RGB): photo colour over Lambertian
/// shading at the centroids of faces in their best views, area weighted, in the
/// linear domain, over the photo's gain and white balance (as BakePhotoTextures).
Eigen::Vector3f MeanAlbedoFromPhotos(const mesh::TriangleMesh& mesh,
                                     const sfm::Reconstruction& reconstruction,
                                     const sfm::VisibilityResult& visibility,
                                     const std::vector<synth::MeshPhoto>& photos,
                                     const std::vector<double>& photo_gains,
                                     const std::vector<std::array<double, 3>>& white_balance = {});

}  // namespace texlume::render
