#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/progress.h"
#include "ptm/light_response.h"

namespace texlume::btf {

/// A measured bidirectional texture function f(x, v, l) of a flat material
/// sample (paper 004 §III), as a grid of images: one per view direction v and
/// light direction l, rectified to the material frame (x right = u, y up = v,
/// z out of the sample; directions are unit vectors towards the viewer / light).
struct BtfCapture {
  int width = 0, height = 0;
  double texel_size = 0.0;  ///< world units per texel
  std::vector<Eigen::Vector3d> views, lights;
  /// The image file of (view a, light b) at a * lights.size() + b, inside the folder.
  std::vector<std::filesystem::path> files;
  /// Image of (view a, light b) at a * lights.size() + b: CV_32FC3 linear RGB.
  std::vector<cv::Mat> images;
  const cv::Mat& Image(std::size_t view, std::size_t light) const {
    return images[view * lights.size() + light];
  }
};

/// The capture that `btf.json` (already parsed, read from `label`) describes,
/// with its image files inside `dir` and no images read: sizes, directions and
/// the size in memory checked, `file_pattern` expanded by texlume (literal text,
/// "%%", and two integer fields "%d" or "%0Nd", view then light; never printf).
/// Throws InputError naming `label` on anything malformed.
BtfCapture ParseBtfJson(const nlohmann::json& btf_json, const std::filesystem::path& dir,
                        const std::string& label);

/// Reads a capture folder: `btf.json` (ParseBtfJson: `size` or `width` / `height`,
/// `texel_size`, `views`, `lights`, `file_pattern` with two integer fields, view
/// then light) and one 8- or 16-bit sRGB image per (view, light),
/// decoded to linear RGB. Throws InputError naming the file on a missing or
/// unreadable image, a size that differs from the stated one, directions that
/// are not unit vectors above the sample, or a malformed btf.json.
BtfCapture ReadBtfCapture(const std::filesystem::path& dir);

/// The SVD factorisation of paper 004 §III,
///   f(x, v, l) ≈ sum_{i<n} g_i(x) p_i(v, l),
/// with the geometry maps g_i (one value per texel) and the eigen point
/// appearance functions p_i (an RGB triple per view and light). The data
/// matrix has one row per texel and one column per (view, light, channel).
struct BtfFactorisation {
  int width = 0, height = 0;
  double texel_size = 0.0;
  std::vector<Eigen::Vector3d> views, lights;
  /// texels x n, row-major texel order (y down, x right) as the capture images.
  Eigen::MatrixXf geometry;
  /// (views * lights * 3) x n: row (a * lights + b) * 3 + c is p_i(v_a, l_b) for channel c.
  Eigen::MatrixXf appearance;
  /// All singular values of the data matrix, largest first (not only the n kept).
  std::vector<double> singular_values;
  int Components() const { return static_cast<int>(geometry.cols()); }
  std::size_t NumTexels() const {
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
};

/// Factorises a capture keeping `components` terms (paper 004: n = 40), in
/// [1, min(texels, views * lights * 3)]; throws OptionError naming the limit
/// otherwise. Deterministic.
BtfFactorisation FactoriseBtf(const BtfCapture& capture, int components,
                              const ProgressCallback& progress = {});

/// A BTF sample folder as a factorisation: a factorisation (btf_svd.json) read
/// as it is, or a capture (btf.json) factorised keeping `components` terms.
/// Throws InputError naming the folder when it holds neither.
BtfFactorisation ReadOrFactoriseBtf(const std::filesystem::path& dir, int components,
                                    const ProgressCallback& progress = {});

/// Reconstruction error with the first n components, from the singular values:
/// RMS over every texel, view, light and channel (linear RGB units), and
/// relative to the RMS of the data.
struct SvdError {
  int components = 0;
  double rms = 0.0, relative = 0.0;
};
std::vector<SvdError> SvdErrorTable(const BtfFactorisation& factorisation,
                                    const std::vector<int>& components);
/// The table at 1, 2, 4, ... components and at all of them (what a model folder records).
std::vector<SvdError> SvdErrorTable(const BtfFactorisation& factorisation);

/// Weights of the grid directions for a query direction (unit, towards the
/// viewer or light): the 3 nearest grid directions by angle, weighted by the
/// inverse square of the angle (a query on a grid direction gets it alone);
/// sums to 1. Used for both views and lights.
std::vector<std::pair<std::size_t, double>> DirectionWeights(
    const std::vector<Eigen::Vector3d>& grid, const Eigen::Vector3d& query);

/// p_i(v, l) for any view and light (material frame), interpolated over the
/// direction grid: n x 3 (component, channel).
Eigen::MatrixX3f InterpolateAppearance(const BtfFactorisation& factorisation,
                                       const Eigen::Vector3d& view, const Eigen::Vector3d& light);

/// A light in the material frame (direction to the light) and its intensity.
using MaterialLight = std::pair<Eigen::Vector3d, double>;
/// sum_l I_l r(l) p_i(v, l) + alpha p_i(v, zenith): the appearance under the
/// lights as the object answers them (ptm::LightResponse: each light above the
/// horizon times the factor at its elevation, and the ambient alpha as a unit
/// light at the zenith). n x 3 (component, channel).
Eigen::MatrixX3f AppearanceUnder(const BtfFactorisation& factorisation, const Eigen::Vector3d& view,
                                 const std::vector<MaterialLight>& lights,
                                 const ptm::LightResponse& response);

/// The factorised BTF as an image (CV_32FC3 linear RGB) for one view and light
/// (interpolated over the grid), using the first `components` terms (0: all).
cv::Mat EvaluateBtf(const BtfFactorisation& factorisation, const Eigen::Vector3d& view,
                    const Eigen::Vector3d& light, int components = 0);

/// Writes a factorisation to a folder, atomically: `geometry_maps.exr` (n float
/// channels g00, g01, ...), `appearance.bin` (float32 little-endian, the
/// appearance matrix row by row) and `btf_svd.json` (sizes, directions,
/// singular values, the error table). See docs/btf.md.
void WriteBtfFactorisation(const BtfFactorisation& factorisation,
                           const std::vector<SvdError>& errors, const std::filesystem::path& dir);

/// Reads what WriteBtfFactorisation wrote. Throws InputError naming the file.
BtfFactorisation ReadBtfFactorisation(const std::filesystem::path& dir);

/// The geometry-map vector (n values) of the sample at a continuous texel
/// position (x right, y down, centres at +0.5), Catmull-Rom (CatmullRomTaps),
/// clamped to the sample.
void SampleGeometry(const BtfFactorisation& sample, const Eigen::Vector2d& sample_px, float* out);

}  // namespace texlume::btf
