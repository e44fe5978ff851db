#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/progress.h"
#include "render/metrics.h"
#include "render/model_render.h"

namespace texlume::pipeline {

/// `texlume render`: the model folder drawn through every image of a COLMAP
/// model that has a light in `lights_file`.
struct RenderJobOptions {
  std::filesystem::path model_folder;
  std::filesystem::path cameras_dir;
  std::filesystem::path lights_file;
  std::filesystem::path out_dir;
  render::RenderMode mode = render::RenderMode::kPtm;
  /// In mode kPtm, a model folder holding a BTF (texlume synth --btf) is drawn
  /// as that BTF (render::RenderBtf) unless this is false (then as its PTM
  /// preview). `texlume render --baseline ptm` sets it false.
  bool btf_as_btf = true;
  int samples_per_axis = 2;
  /// Optional ground truth: images (and masks) with the same names; PSNR and
  /// SSIM inside the masks go into render.json.
  std::filesystem::path truth_images_dir, truth_masks_dir;
  /// Also compare after reducing both by this factor (the constraint photos'
  /// resolution when the views are rendered finer); 1 = off.
  int reduced_factor = 1;

  /// Throws OptionError when a path is missing or a setting is out of range.
  void Check() const;
  /// The settings as render.json records them ("mode" as asked; the job
  /// records the mode it drew in).
  nlohmann::json ToJson() const;
};

struct RenderJobSummary {
  std::size_t rendered = 0;
  std::vector<std::string> warnings;
  std::vector<render::ViewMetrics> metrics;  ///< with truth
  double mean_psnr = 0, mean_ssim = 0, mean_psnr_reduced = 0, mean_ssim_reduced = 0;
  render::FidelityMetrics mean_fidelity;  ///< each figure averaged over the views
  double seconds = 0;
};

/// `rgb` (CV_32FC3 display RGB) against truth_images_dir/image_name inside
/// truth_masks_dir/image_name when that mask exists, else inside `coverage`
/// (CV_8UC1). Throws InputError naming a truth image or mask that cannot be read
/// or is not of the rendering's size.
render::ViewMetrics MeasureAgainstTruth(const std::string& image_name, const cv::Mat& rgb,
                                        const cv::Mat& coverage,
                                        const std::filesystem::path& truth_images_dir,
                                        const std::filesystem::path& truth_masks_dir,
                                        int reduced_factor);

/// Renders the views (PNG, with a coverage mask in masks/), measures them
/// against the truth when given, and writes render.json (settings, per-view
/// and mean metrics, timings). Throws InputError when no image has a light or
/// a truth image or mask does not match.
RenderJobSummary RunRenderJob(const RenderJobOptions& options,
                              const ProgressCallback& progress = {});

}  // namespace texlume::pipeline
