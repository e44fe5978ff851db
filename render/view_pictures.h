#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "ptm/ptm.h"
#include "render/model_render.h"
#include "sfm/camera_models.h"
#include "sfm/lights.h"
#include "sfm/reconstruction.h"

namespace texlume::render {

/// A view to draw the model from, with the reference picture to set beside it.
struct PictureView {
  std::string name;
  sfm::Camera camera;
  sfm::Rigid3d cam_from_world;
  std::vector<sfm::ObjectLight> lights;
  /// The reference (ground truth or the photo); empty = none.
  std::filesystem::path reference_image;
  /// The reference already in memory (CV_32FC3 display RGB, the camera's size);
  /// used instead of reading `reference_image`, which then only names it.
  cv::Mat reference;
  /// Its object mask; empty = where the model covers the pixel.
  std::filesystem::path reference_mask;
  /// The reference's exposure relative to the model (a photo's gain, linear
  /// domain); the reference is divided by it before comparing.
  double reference_gain = 1.0;
};

/// One view drawn at the pictures' resolution: the reference (divided by its
/// gain) and each model, with PSNR (dB) and SSIM inside the mask.
struct ViewPictures {
  std::string name;
  std::vector<sfm::ObjectLight> lights;
  cv::Mat reference;  ///< CV_32FC3 display RGB; empty = the view had none
  cv::Mat inside;     ///< CV_8UC1, 255 inside the mask; empty without a reference
  struct Drawn {
    std::string model;  ///< "texlume", "flat", "baked"
    cv::Mat rgb;        ///< CV_32FC3 display RGB
    double psnr = 0, ssim = 0;
  };
  std::vector<Drawn> drawn;
  /// World units one picture pixel spans at the depth of the model's bounding-box
  /// centre (WorldPerPixelAt); 0 when the centre is not in front of the camera.
  double world_per_pixel = 0.0;
};

/// World units one pixel of `camera` spans, across the viewing direction, at the depth
/// of `point_in_world`: its depth over the mean focal length (pinhole approximation,
/// distortion ignored). 0 when the point is not in front of the camera.
double WorldPerPixelAt(const sfm::Camera& camera, const sfm::Rigid3d& cam_from_world,
                       const Eigen::Vector3d& point_in_world);

/// Draws `view` at most `width` pixels wide (the camera scaled down) in each
/// (name, mode), 2 x 2 rays per pixel, and measures each against the reference
/// inside its mask (else where the model covers the pixel). Throws InputError
/// naming the reference or mask when it does not match the camera's size.
ViewPictures DrawView(const ModelRenderer& renderer,
                      const std::vector<std::pair<std::string, RenderMode>>& modes,
                      const PictureView& view, int width);

/// The model from `view` at most `width` pixels wide under one directional
/// light circling the viewing axis at `elevation_deg` above the image plane:
/// `frames` pictures (CV_32FC3 display RGB), starting at the right and turning
/// counter-clockwise.
std::vector<cv::Mat> DrawLightSweep(const ModelRenderer& renderer, const PictureView& view,
                                    int width, int frames, double elevation_deg);

/// The sample PTM relit in its own frame, at most `width` texels wide: head-on,
/// then four lights around it at `elevation_deg` (CV_32FC3 display RGB).
std::vector<std::pair<Eigen::Vector3d, cv::Mat>> RelightSample(const ptm::Ptm& sample, int width,
                                                               double elevation_deg);

/// `image` scaled down (area averaging) to `width` pixels wide, its aspect
/// kept; a copy when it is no wider.
cv::Mat ResizedToWidth(const cv::Mat& image, int width);

/// `count` of `n` items, evenly spread (the first always).
std::vector<std::size_t> EvenlySpread(std::size_t n, int count);

}  // namespace texlume::render
