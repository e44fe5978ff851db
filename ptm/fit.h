#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <vector>

#include "core/progress.h"
#include "ptm/ptm.h"

namespace texlume::ptm {

/// Settings of the PTM fit.
struct FitOptions {
  PtmFormat format = PtmFormat::kLrgb;
  /// Robust fit with Ceres (Cauchy loss, saturated and black samples dropped), so
  /// shadows and highlights do not pull the polynomial. Slower: one small
  /// problem per texel.
  bool robust = false;
  /// Cauchy loss scale, intensity units of [0, 1]. (0, 1].
  double robust_scale = 0.03;
  /// Robust fit only: samples at or above this in any channel are saturated. (0, 1].
  double saturation_threshold = 0.995;
  /// Robust fit only: samples at or below this (all channels) are in full shadow. [0, 1).
  double shadow_threshold = 0.01;
  /// Rows per band when streaming images from files; memory ~ images x band. >= 1.
  int band_rows = 32;
  /// Fewest lights accepted (6 coefficients need at least 6). >= 6.
  int min_lights = 6;
  /// Light sets whose normal matrix A^T A has a larger condition number are
  /// degenerate (for example all lights on one line). > 1.
  double max_condition_number = 1e7;

  void Check() const;
};

/// A fitted PTM with its fit residuals.
struct FitResult {
  Ptm ptm;
  /// Per texel, row-major: RMS over lights and channels of fit minus image.
  std::vector<float> residual_rms;
  double mean_residual_rms = 0.0;
  std::size_t num_images = 0;
  double seconds = 0.0;
};

/// Images in memory: float RGB in [0, 1], row-major, 3 floats per pixel, all of
/// one size.
struct ImageRgb {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;
};

/// Fits a PTM to images that share light directions (unit, tangent frame: x
/// right, y up, z out; z > 0): one pseudo-inverse of the 6-column light matrix,
/// then one product per texel (closed-form least squares), or the robust fit.
/// LRGB colour is the luminance-weighted mean chromaticity over the lights.
/// Throws InputError(label, ...) for bad light sets or image sizes.
FitResult FitPtm(const std::vector<ImageRgb>& images, const std::vector<Eigen::Vector3d>& lights,
                 const FitOptions& options, const std::string& label = "images");

/// The same from image files (PNG, JPEG, TIFF, EXR... through OpenImageIO),
/// streamed by bands of rows: memory holds the output and one band of every
/// image, never whole images. Throws InputError naming a missing or unreadable
/// file, or one whose size differs from the first.
FitResult FitPtmFromFiles(const std::vector<std::filesystem::path>& files,
                          const std::vector<Eigen::Vector3d>& lights, const FitOptions& options,
                          const ProgressCallback& progress = {});

/// Fits a PTM when light directions differ per texel (point lights, or lights in
/// the tangent frames of a mesh): per-texel normal equations.
/// `light_at(image, x, y)` gives the unit direction (tangent frame) of image
/// `image` at texel (x, y); texels with fewer than 6 lights above the horizon
/// (or degenerate ones) get the mean intensity as a constant.
FitResult FitPtmPerTexelLights(
    const std::vector<ImageRgb>& images,
    const std::function<Eigen::Vector3d(int image, int x, int y)>& light_at,
    const FitOptions& options);

/// An RTI capture on disk: image files and their light directions, in .lp order.
struct RtiCapture {
  std::vector<std::filesystem::path> files;
  std::vector<Eigen::Vector3d> lights;
  /// Names the .lp gives that were found only ignoring case (a capture made on Windows).
  std::vector<std::string> warnings;
};

/// Reads an .lp file and finds each image it names in `images_dir` (by file name).
/// A name with no file of that exact name takes the one file whose name matches it
/// ignoring case, with a warning. Throws InputError naming the .lp and the image
/// when there is none, or several.
RtiCapture ReadRtiCapture(const std::filesystem::path& lp_path,
                          const std::filesystem::path& images_dir);

/// Checks a light set: at least options.min_lights, every light unit, above the
/// horizon, and the light matrix well conditioned. Throws InputError(label, ...).
void CheckLightSet(const std::vector<Eigen::Vector3d>& lights, const FitOptions& options,
                   const std::string& label);

/// The same for any basis of the hemisphere (PTM, HSH): `basis_rows` holds the basis at
/// each light (a row per light). At least `min_lights` lights, each a unit vector above
/// the horizon, and the normal equations' condition number (the rows' squared) at most
/// `max_condition_number`. `basis` names it in the messages ("a PTM", "an order-3 HSH").
/// Throws InputError(label, ...).
void CheckLightsForBasis(const std::vector<Eigen::Vector3d>& lights,
                         const Eigen::MatrixXd& basis_rows, std::size_t min_lights,
                         double max_condition_number, const std::string& basis,
                         const std::string& label);

}  // namespace texlume::ptm
