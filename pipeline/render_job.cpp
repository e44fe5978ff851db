#include "pipeline/render_job.h"

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "core/partial_output.h"
#include "core/timing.h"
#include "model/baselines.h"
#include "model/btf_model.h"
#include "model/model_io.h"
#include "render/btf_shading.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;

void RenderJobOptions::Check() const {
  for (const auto& [path, what] :
       {std::pair{&model_folder, "model folder"}, std::pair{&cameras_dir, "COLMAP model folder"},
        std::pair{&lights_file, "lights file"}, std::pair{&out_dir, "output folder"}})
    if (path->empty()) throw OptionError(std::string("render needs a ") + what);
  if (samples_per_axis < 1 || samples_per_axis > 8) throw OptionError("samples must be in [1, 8]");
  if (reduced_factor < 1 || reduced_factor > 16)
    throw OptionError("reduced factor must be in [1, 16]");
  if (!truth_masks_dir.empty() && truth_images_dir.empty())
    throw OptionError("truth masks need truth images");
}

nlohmann::json RenderJobOptions::ToJson() const {
  nlohmann::json settings = {
      {"model", model_folder.string()},  {"cameras", cameras_dir.string()},
      {"lights", lights_file.string()},  {"mode", render::RenderModeName(mode)},
      {"btf_as_btf", btf_as_btf},        {"samples_per_axis", samples_per_axis},
      {"reduced_factor", reduced_factor}};
  if (!truth_images_dir.empty()) settings["truth_images"] = truth_images_dir.string();
  if (!truth_masks_dir.empty()) settings["truth_masks"] = truth_masks_dir.string();
  return settings;
}

namespace {

// A view's appearance figures as render.json records them (render/fidelity.h).
nlohmann::json FidelityJson(const render::FidelityMetrics& f) {
  return {{"luma_bias", f.luma_bias},
          {"linear_luma_bias", f.linear_luma_bias},
          {"chroma_spread_ratio", f.chroma_spread_ratio},
          {"gradient_histogram_distance", f.gradient_histogram_distance},
          {"gradient_p90", f.gradient_p90},
          {"gradient_p90_truth", f.gradient_p90_truth},
          {"power_spectrum_db", f.power_spectrum_db}};
}

fs::path PngName(const std::string& image_name) {
  fs::path p(image_name);
  p.replace_extension(".png");
  return p;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  fs::create_directories(path.parent_path());
  WriteBytesAtomically(path, EncodePng(image, path.string()));
}

// The render job's steps, each a method (RunRenderJob).
class RenderJob {
 public:
  RenderJob(const RenderJobOptions& options, const ProgressCallback& progress)
      : options_(options), progress_(progress) {}

  RenderJobSummary Run() {
    const auto start = std::chrono::steady_clock::now();
    AnnounceStep(progress_, "reading the model folder");
    LoadModel();
    LoadViews();
    RequireReplaceableFolder(options_.out_dir, "render.json", "a texlume render folder");
    output_.emplace(options_.out_dir, PartialOutput::Kind::kFolder);
    std::size_t done = 0;
    const std::size_t total = cameras_.reconstruction.images.size();
    for (const auto& [id, image] : cameras_.reconstruction.images) {
      ++done;
      if (const auto it = lights_.find(image.name); it != lights_.end())
        RenderView(image, it->second);
      if (progress_) progress_("render", done, total);
    }
    if (summary_.rendered == 0)
      throw InputError(options_.lights_file.string(),
                       "gives a light for no image of " + options_.cameras_dir.string());
    AverageMetrics();
    summary_.seconds = SecondsSince(start);
    WriteRecord();
    output_->Commit();
    return summary_;
  }

 private:
  // The model folder, its baselines when drawn as one, its BTF when drawn as one.
  void LoadModel() {
    model_ = model::ReadModelFolder(options_.model_folder);
    renderer_.emplace(model_);
    if (options_.mode == render::RenderMode::kPtm && options_.btf_as_btf &&
        model::ReadModelManifest(options_.model_folder).contains("btf")) {
      btf_ = std::make_unique<model::BtfModel>(model::ReadBtfModel(options_.model_folder, model_));
    } else if (options_.mode != render::RenderMode::kPtm) {
      model::ModelBaselines baselines = model::ReadModelBaselines(options_.model_folder, model_);
      renderer_->flat_albedo = baselines.flat_albedo;
      renderer_->baked = std::move(baselines.baked);
    }
  }

  void LoadViews() {
    cameras_ = sfm::ReadModel(options_.cameras_dir);
    if (!cameras_.choice.empty()) summary_.warnings.push_back(cameras_.choice);
    // A view's buffers (colour, coverage, depth, rays and the truth): about 64 bytes a pixel.
    for (const auto& [id, camera] : cameras_.reconstruction.cameras) {
      RequireMemory(64.0 * static_cast<double>(camera.width) * static_cast<double>(camera.height),
                    "rendering a view of camera " + std::to_string(id.value),
                    options_.cameras_dir.string());
    }
    lights_ = sfm::ReadObjectLightsFile(options_.lights_file);
    const sfm::LightsModelMatch match = sfm::CheckLightsAgainstModel(
        lights_, cameras_.reconstruction, options_.lights_file.string());
    for (const std::string& name : match.images_without_lights)
      summary_.warnings.push_back("not rendering " + name + ": no light for it");
    for (const std::string& name : match.lights_without_images)
      summary_.warnings.push_back("ignoring the light of " + name + ": no camera for it");
  }

  void RenderView(const sfm::Image& image, const std::vector<sfm::ObjectLight>& lights) {
    const sfm::Camera& camera = cameras_.reconstruction.cameras.at(image.camera_id);
    const render::RenderedView view =
        btf_ ? render::RenderBtf(*renderer_, *btf_, camera, image.cam_from_world, lights,
                                 options_.samples_per_axis)
             : renderer_->Render(camera, image.cam_from_world, lights, options_.mode,
                                 options_.samples_per_axis);
    const fs::path name = PngName(image.name);
    WritePng(output_->path() / name, ToBgr8(view.rgb));
    cv::Mat mask;
    view.coverage.convertTo(mask, CV_8UC1, 255.0);
    WritePng(output_->path() / "masks" / name, mask);
    ++summary_.rendered;
    if (!options_.truth_images_dir.empty()) Measure(image.name, view.rgb, mask);
  }

  void Measure(const std::string& image_name, const cv::Mat& rgb, const cv::Mat& coverage) {
    summary_.metrics.push_back(
        MeasureAgainstTruth(image_name, rgb, coverage, options_.truth_images_dir,
                            options_.truth_masks_dir, options_.reduced_factor));
  }

  void AverageMetrics() {
    const render::ViewMetrics mean = render::MeanViewMetrics(summary_.metrics);
    summary_.mean_psnr = mean.psnr;
    summary_.mean_ssim = mean.ssim;
    summary_.mean_psnr_reduced = mean.psnr_reduced;
    summary_.mean_ssim_reduced = mean.ssim_reduced;
    summary_.mean_fidelity = mean.fidelity;
  }

  nlohmann::json MetricsJson() const {
    nlohmann::json views = nlohmann::json::array();
    for (const render::ViewMetrics& m : summary_.metrics)
      views.push_back({{"name", m.name},
                       {"psnr_db", m.psnr},
                       {"ssim", m.ssim},
                       {"psnr_reduced_db", m.psnr_reduced},
                       {"ssim_reduced", m.ssim_reduced},
                       {"fidelity", FidelityJson(m.fidelity)}});
    return {{"views", views},
            {"mean_psnr_db", summary_.mean_psnr},
            {"mean_ssim", summary_.mean_ssim},
            {"mean_psnr_reduced_db", summary_.mean_psnr_reduced},
            {"mean_ssim_reduced", summary_.mean_ssim_reduced},
            {"mean_fidelity", FidelityJson(summary_.mean_fidelity)},
            {"reduced_factor", options_.reduced_factor},
            {"inside", "the ground-truth masks"}};
  }

  void WriteRecord() const {
    nlohmann::json record;
    record["command"] = "render";
    record["settings"] = options_.ToJson();
    record["settings"]["mode"] = btf_ ? "btf" : render::RenderModeName(options_.mode);
    record["rendered"] = summary_.rendered;
    record["warnings"] = summary_.warnings;
    if (!summary_.metrics.empty()) record["metrics"] = MetricsJson();
    record["timings_s"] = {{"total", summary_.seconds}};
    WriteFileAtomically(
        output_->path() / "render.json", [&](std::ostream& o) { o << record.dump(2) << "\n"; },
        false);
  }

  const RenderJobOptions& options_;
  const ProgressCallback& progress_;
  RenderJobSummary summary_;
  model::TexturedModel model_;
  std::optional<render::ModelRenderer> renderer_;
  std::unique_ptr<model::BtfModel> btf_;
  sfm::LoadedModel cameras_;
  sfm::ObjectLights lights_;
  std::optional<PartialOutput> output_;  // the output folder while it is written
};

}  // namespace

render::ViewMetrics MeasureAgainstTruth(const std::string& image_name, const cv::Mat& rgb,
                                        const cv::Mat& coverage, const fs::path& truth_images_dir,
                                        const fs::path& truth_masks_dir, int reduced_factor) {
  const fs::path truth_path = truth_images_dir / image_name;
  const cv::Mat truth = ReadPhotoRgb(truth_path);
  if (truth.size() != rgb.size())
    throw InputError(truth_path.string(), "does not match the camera's size");
  cv::Mat truth_mask;
  const fs::path mask_path = truth_masks_dir.empty() ? fs::path() : truth_masks_dir / image_name;
  if (!mask_path.empty() && fs::exists(mask_path)) {
    truth_mask = ReadImageGrey(mask_path) > 0.5f;
    if (truth_mask.size() != truth.size())
      throw InputError(mask_path.string(), "does not match its image's size");
  } else {
    truth_mask = coverage > 127;
  }
  return render::MeasureView(image_name, rgb, truth, truth_mask > 127, reduced_factor);
}

RenderJobSummary RunRenderJob(const RenderJobOptions& options, const ProgressCallback& progress) {
  options.Check();
  return RenderJob(options, progress).Run();
}

}  // namespace texlume::pipeline
