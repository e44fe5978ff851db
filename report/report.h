#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/progress.h"
#include "model/model_io.h"
#include "ptm/ptm.h"
#include "render/metrics.h"
#include "render/view_pictures.h"
#include "sfm/lights.h"

namespace texlume::report {

/// A photo shown among the constraint photos.
struct ReportPhoto {
  std::string name;
  std::filesystem::path file;
  std::vector<sfm::ObjectLight> lights;
  cv::Mat image;  ///< CV_32FC3 display RGB when already in memory; else `file` is read
};

/// Light directions to plot on the hemisphere, in a frame whose z is up (the zenith)
/// and whose x is azimuth 0; azimuth grows counter-clockwise seen from above (toward y).
struct LightPlot {
  std::string title;
  std::string frame;  ///< what z and x are, in words
  std::vector<Eigen::Vector3d> directions;
};

/// Mean metrics of one model over the held-out views, as `texlume render`
/// measured them (full resolution and reduced).
struct ReportMetrics {
  std::string label;
  std::vector<render::ViewMetrics> views;
  double mean_psnr = 0, mean_ssim = 0, mean_psnr_reduced = 0, mean_ssim_reduced = 0;
};

/// Everything the report shows, already drawn and measured (the report draws
/// nothing: pipeline::DrawReportPictures renders the pictures). Pointers are
/// borrowed for the call.
struct ReportInputs {
  std::string title;
  std::string intro;                            ///< one paragraph of plain text
  const model::TexturedModel* model = nullptr;  ///< required: its atlases are shown
  /// The material sample relit in its own frame (render::RelightSample), and
  /// its size in texels; empty = no sample section.
  std::vector<std::pair<Eigen::Vector3d, cv::Mat>> sample_relit;
  int sample_width = 0, sample_height = 0;
  std::vector<ReportPhoto> photos;          ///< the constraint photos
  std::vector<LightPlot> light_plots;       ///< hemisphere plots of lights (capture, photos)
  int max_photos = 12;                      ///< at most this many are shown, evenly spread
  std::vector<render::ViewPictures> views;  ///< the views drawn (render::DrawView)
  std::size_t views_total = 0;              ///< of how many views they were picked
  std::string views_heading;                ///< e.g. "Held-out views under held-out lights"
  /// The light sweep (render::DrawLightSweep) from view `sweep_view`; empty = none.
  std::vector<cv::Mat> sweep;
  std::string sweep_view;
  double sweep_elevation_deg = 40.0;
  std::vector<ReportMetrics> metrics;                      ///< optional full-resolution tables
  std::vector<std::pair<std::string, std::string>> facts;  ///< summary lines (name, value)
  std::vector<std::pair<std::string, double>> timings_s;   ///< stage, seconds
  std::vector<std::pair<std::string, std::string>> links;  ///< label, href relative to the report
  /// Where the results came from: the inputs (name, file) whose CRC-32 the page shows,
  /// beside texlume's version and the recorded command line (core/provenance.h).
  std::vector<std::pair<std::string, std::filesystem::path>> inputs;
  /// The model folder as the command that previews it names it (`texlume view DIR`);
  /// empty = no pointer.
  std::string view_folder;
  double occupancy = 0.0;  ///< of the whole layout (atlas texels inside triangles)
  /// Physical scale: the sample's and the atlases' texel size in world units (0 = unknown:
  /// no scale shown), and how long one world unit is in millimetres (`--world-unit`; 0 =
  /// not stated: lengths in world units only). The views' scale is their
  /// `world_per_pixel`.
  double texel_size = 0.0;
  double mm_per_world_unit = 0.0;
  /// Error maps run from black (0) to white at this mean absolute difference
  /// (display values in [0, 1]).
  double error_map_max = 0.25;
};

/// The report's pictures and the metrics it showed.
struct ReportSummary {
  std::size_t pictures = 0;
  /// Per drawn view and model ("texlume", "flat", "baked"): PSNR (dB) and SSIM
  /// against the reference inside its mask, at the pictures' resolution (as
  /// render::DrawView measured them).
  struct Row {
    std::string view, model;
    double psnr = 0, ssim = 0;
  };
  std::vector<Row> rows;
  double seconds = 0;
};

/// Writes `dir`/report.html and its pictures in `dir`/report/: provenance (version,
/// command line, input checksums) and a pointer to `texlume view`, the sample
/// relit at a few lights, the constraint photos, the model from the views
/// beside the reference and the baselines, error maps (mean absolute
/// difference over the channels), the light-sweep strip, atlas thumbnails with
/// the triangle outlines and occupancy, and the metrics and timings tables, saying
/// where a baseline does better than texlume. The
/// pictures are written to a temporary folder renamed into place, then the
/// page atomically; relative links only, so the folder opens from disk.
ReportSummary WriteReport(const std::filesystem::path& dir, const ReportInputs& inputs,
                          const ProgressCallback& progress = {});

/// Texels inside the model's triangles over the atlas's texels, per atlas
/// (triangles rasterised at their texture coordinates: the texels of
/// model::AtlasChartRegions' charts).
std::vector<double> AtlasOccupancies(const model::TexturedModel& model);

/// Escapes text for HTML (& < > " ').
std::string HtmlEscape(const std::string& text);

}  // namespace texlume::report
