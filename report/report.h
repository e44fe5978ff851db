#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/progress.h"
#include "ptm/ptm.h"
#include "sfm/camera_models.h"
#include "sfm/lights.h"
#include "sfm/reconstruction.h"
#include "model/model_io.h"
#include "render/metrics.h"

namespace texlume::report {

/// A view the report draws the model from, beside its reference picture.
struct ReportView {
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

/// A photo shown among the constraint photos.
struct ReportPhoto {
  std::string name;
  std::filesystem::path file;
  std::vector<sfm::ObjectLight> lights;
  cv::Mat image;  ///< CV_32FC3 display RGB when already in memory; else `file` is read
};

/// Mean metrics of one model over the held-out views, as `texlume render`
/// measured them (full resolution and reduced).
struct ReportMetrics {
  std::string label;
  std::vector<render::ViewMetrics> views;
  double mean_psnr = 0, mean_ssim = 0, mean_psnr_reduced = 0, mean_ssim_reduced = 0;
};

/// Everything the report shows. Pointers are borrowed for the call.
struct ReportInputs {
  std::string title;
  std::string intro;                     ///< one paragraph of plain text
  const model::TexturedModel* model = nullptr;  ///< required
  Eigen::Vector3f flat_albedo = Eigen::Vector3f::Constant(0.5f);
  std::vector<cv::Mat> baked;          ///< per atlas (display RGB); empty = no baked column
  const ptm::Ptm* sample = nullptr;    ///< the material sample; null = no sample section
  std::vector<ReportPhoto> photos;     ///< the constraint photos
  std::vector<ReportView> views;       ///< at most `max_views` are drawn, evenly spread
  std::string views_heading;           ///< e.g. "Held-out views under held-out lights"
  std::vector<ReportMetrics> metrics;  ///< optional full-resolution tables
  std::vector<std::pair<std::string, std::string>> facts;  ///< summary lines (name, value)
  std::vector<std::pair<std::string, double>> timings_s;   ///< stage, seconds
  std::vector<std::pair<std::string, std::string>> links;  ///< label, href relative to the report
  double occupancy = 0.0;  ///< of the whole layout (atlas texels inside triangles)
  int max_views = 4;
  int max_photos = 12;
  int picture_width = 300;  ///< pixels; views are rendered at (at most) this width
  int sweep_frames = 8;
  /// Error maps run from black (0) to white at this mean absolute difference
  /// (display values in [0, 1]).
  double error_map_max = 0.25;
};

/// What the report measured on its own pictures.
struct ReportSummary {
  std::size_t pictures = 0;
  /// Per drawn view and model ("texlume", "flat", "baked"): PSNR (dB) and SSIM
  /// against the reference inside its mask, at the pictures' resolution.
  struct Row {
    std::string view, model;
    double psnr = 0, ssim = 0;
  };
  std::vector<Row> rows;
  double seconds = 0;
};

/// Writes `dir`/report.html and its pictures in `dir`/report/: the sample
/// relit at a few lights, the constraint photos, the model from the views
/// beside the reference and both baselines, error maps (mean absolute
/// difference over the channels), a light-sweep strip (the first view, a light
/// circling at 35 degrees above the image plane), atlas thumbnails with the
/// triangle outlines and occupancy, and the metrics and timings tables. The
/// pictures are written to a temporary folder renamed into place, then the
/// page atomically; relative links only, so the folder opens from disk.
ReportSummary WriteReport(const std::filesystem::path& dir, const ReportInputs& inputs,
                          const ProgressCallback& progress = {});

/// Texels inside the model's triangles over the atlas's texels, per atlas
/// (triangles rasterised at their texture coordinates).
std::vector<double> AtlasOccupancies(const model::TexturedModel& model);

/// Escapes text for HTML (& < > " ').
std::string HtmlEscape(const std::string& text);

}  // namespace texlume::report
