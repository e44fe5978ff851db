#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "datasets_synthetic/material.h"
#include "datasets_synthetic/shapes.h"
#include "sfm/camera_models.h"
#include "sfm/reconstruction.h"

namespace texlume::datasets {

/// True displaced geometry of one or more surface patches: a fine triangle mesh
/// whose vertices are the base surface moved along its normal by the material
/// height, with per-vertex shading attributes.
struct DisplacedGeometry {
  std::vector<Eigen::Vector3f> positions;  ///< world frame
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Eigen::Vector2f> uv;            ///< material coordinates, world units
  std::vector<Eigen::Vector3f> normal;        ///< base-surface normal
  std::vector<Eigen::Vector3f> d_du;          ///< base-surface dS/du
  std::vector<Eigen::Vector3f> d_dv;          ///< base-surface dS/dv
  std::vector<std::uint16_t> triangle_patch;  ///< which patch (and material) a triangle is
};

/// Tessellates every patch with edges of about `step` world units and displaces
/// it by its material (materials[i] for patches[i]).
DisplacedGeometry DisplacePatches(const std::vector<SurfacePatch>& patches,
                                  const std::vector<const BakedMaterial*>& materials, double step);

/// A directional light of a rendering: unit direction from the surface towards
/// the light (world frame) and its intensity.
struct RenderLight {
  Eigen::Vector3d direction_in_world = Eigen::Vector3d::UnitZ();
  double intensity = 1.0;
};

/// Shading settings: Lambert plus Blinn-Phong and sheen (from the material), cast
/// and self shadows from the displaced geometry, an ambient term, optionally one
/// bounce of diffuse interreflection.
struct ShadingOptions {
  /// Ambient light as a fraction of the albedo, [0, 1].
  double ambient = 0.02;
  /// Multiplies the linear radiance (camera exposure x light scale), > 0.
  double exposure = 1.0;
  /// Samples per pixel along each axis (stratified, fixed positions): n x n per pixel. [1, 8].
  int samples_per_axis = 2;
  bool shadows = true;
  /// One bounce of diffuse interreflection: this many cosine-distributed rays
  /// per sample gather the Lambertian light of the surface they meet (lit
  /// directly, with shadows). 0 = off. [0, 64].
  int interreflection_rays = 0;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// A rendered image: linear RGB radiance (CV_32FC3, R G B order) and the share of
/// each pixel's samples that hit the object (CV_32FC1, 0..1).
struct Rendering {
  cv::Mat linear_rgb;
  cv::Mat coverage;
};

/// Ray caster (Embree) over displaced geometry. Deterministic: the same inputs
/// give the same pixels, whatever the thread count.
class Renderer {
 public:
  /// @param materials  material per patch id of `geometry.triangle_patch`; must
  ///   outlive the renderer
  Renderer(DisplacedGeometry geometry, std::vector<const BakedMaterial*> materials);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// A photo from a COLMAP camera (with its distortion) at pose cam_from_world.
  Rendering RenderPerspective(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                              const std::vector<RenderLight>& lights,
                              const ShadingOptions& options) const;

  /// An orthographic view of a flat sample in the z = 0 plane, rectified to the
  /// material frame: pixel (x, y) covers u in [u0 + x t, u0 + (x+1) t] and
  /// v in [v_top - (y+1) t, v_top - y t] (image rows go down, v up), t = texel size.
  /// The view comes from `view_direction` (unit, towards the viewer; (0,0,1) =
  /// straight down onto the sample); with parallax, a tilted view sees each
  /// texel's relief from the side, as a BTF measurement does.
  Rendering RenderOrthographic(int width, int height, double u0, double v_top, double texel_size,
                               const Eigen::Vector3d& view_direction,
                               const std::vector<RenderLight>& lights,
                               const ShadingOptions& options) const;

  std::size_t NumTriangles() const { return geometry_.triangles.size(); }

 private:
  struct Impl;
  template <typename RayAt>
  Rendering Render(int width, int height, const RayAt& ray_at,
                   const std::vector<RenderLight>& lights, const ShadingOptions& options) const;

  DisplacedGeometry geometry_;
  std::vector<const BakedMaterial*> materials_;
  std::unique_ptr<Impl> impl_;
};

/// Linear RGB (CV_32FC3, R G B) to 8-bit sRGB in OpenCV's B G R order, for imwrite.
cv::Mat LinearToSrgb8(const cv::Mat& linear_rgb);
/// 8-bit sRGB (B G R, as imread gives) to linear RGB (CV_32FC3, R G B).
cv::Mat Srgb8ToLinear(const cv::Mat& srgb_bgr);

}  // namespace texlume::datasets
