#include "pipeline/quilt_job.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>

#include "atlas/btf_atlas.h"
#include "btf/btf.h"
#include "core/errors.h"
#include "core/memory_budget.h"
#include "core/timing.h"
#include "core/units.h"
#include "mesh/mesh.h"
#include "model/btf_model.h"
#include "model/model_io.h"
#include "pipeline/report_pictures.h"
#include "pipeline/synth_job.h"
#include "quilt/quilt_atlases.h"
#include "quilt/vector_field.h"
#include "report/report.h"
#include "synth/btf_sample.h"
#include "synth/colour_sample.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;

void QuiltJobOptions::Check() const {
  for (const auto& [path, what] :
       {std::pair{&mesh_file, "--mesh"}, std::pair{&sample_file, "--sample"},
        std::pair{&out_dir, "--out"}})
    if (path->empty()) throw OptionError(std::string("synth --engine graphcut needs ") + what);
  if (!(sample_texel_size > 0.0 || (sample_texel_size == 0.0 && BtfSample())) ||
      !std::isfinite(sample_texel_size))
    throw OptionError("synth --engine graphcut needs --sample-texel-size > 0");
  if (BtfSample() && btf_components < 1) throw OptionError("--components must be >= 1");
  quilt.Check();
  if (quilt.random_orientation && !field_file.empty())
    throw OptionError("give --field or --orientation random, not both");
  if (!field_direction_in_world.allFinite() || !(field_direction_in_world.norm() > 0))
    throw OptionError("--tangent-field must be a non-zero direction");
  atlas.Check();
  CheckWorldUnit(mm_per_world_unit);
}

bool QuiltJobOptions::BtfSample() const {
  std::error_code error;
  return fs::is_directory(sample_file, error);
}

nlohmann::json QuiltJobOptions::ToJson() const {
  return {
      {"engine", "graphcut"},
      {"sample_texel_size", sample_texel_size},
      {"work_patch_levels", quilt.work_patch_levels},
      {"min_work_patch_levels", quilt.min_work_patch_levels},
      {"work_patch_shrink", quilt.shrink},
      {"max_area_distortion", quilt.max_area_distortion},
      {"seam_threshold", quilt.seam_threshold},
      {"orientation", quilt.random_orientation ? "random"
                      : field_file.empty()     ? "world-direction"
                                               : "field"},
      {"field_direction_in_world",
       {field_direction_in_world.x(), field_direction_in_world.y(), field_direction_in_world.z()}},
      {"field", field_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(field_file.string())},
      {"seed", quilt.seed},
      {"atlas_size", atlas.atlas_size},
      {"gutter", atlas.gutter},
      {"chart_flattening", atlas::ChartFlatteningName(atlas.flattening)},
      {"max_chart_stretch", atlas.max_chart_stretch},
      {"write_report", write_report},
      {"world_unit_mm", WorldUnitJson(mm_per_world_unit)}};
}

namespace {

// The job's steps, each a method (RunQuiltJob).
class QuiltJob {
 public:
  QuiltJob(const QuiltJobOptions& options, const ProgressCallback& progress)
      : options_(options), progress_(progress), quilt_options_(options.quilt) {}

  QuiltJobSummary Run() {
    const auto start = std::chrono::steady_clock::now();
    RefuseForeignModelFolder(options_.out_dir);
    AnnounceStep(progress_, "reading the inputs");
    Load();
    LayOut();
    Quilt();
    Bake();
    AnnounceStep(progress_, "writing the model folder");
    Write();
    summary_.seconds_total = SecondsSince(start);
    return summary_;
  }

 private:
  void Load() {
    mesh::LoadedMesh loaded = mesh::LoadMesh(options_.mesh_file);
    for (const std::string& problem : loaded.report.Problems())
      summary_.warnings.push_back(options_.mesh_file.string() + ": " + problem);
    mesh_ = std::move(loaded.mesh);
    if (mesh_.faces.empty()) throw InputError(options_.mesh_file.string(), "has no triangles");
    summary_.faces = mesh_.faces.size();
    texel_size_ = options_.sample_texel_size;
    if (texel_size_ > 0) RequireSurfaceMemory(3);  // before the sample is read, at least
    LoadSample();
    RefuseSampleLargerThanMesh(mesh_, texel_size_, options_.mesh_file);
    RequireSurfaceMemory(matched_->NumFeatures());
    RefuseSampleSmallerThanWorkPatch();
    RequireCopyMemory();
    if (!options_.field_file.empty())
      quilt_options_.field_in_world =
          quilt::InterpolateField(mesh_, quilt::ReadFieldFile(options_.field_file, mesh_));
  }

  // The sample, and the one the quilting matches: a BTF (its geometry maps), a
  // colour image, or a PTM.
  void LoadSample() {
    const auto start = std::chrono::steady_clock::now();
    AnnounceStep(progress_, "reading the sample");
    if (options_.BtfSample()) {
      btf_ = btf::ReadOrFactoriseBtf(options_.sample_file, options_.btf_components, progress_);
      if (texel_size_ == 0) texel_size_ = btf_.texel_size;
      if (!(texel_size_ > 0) || !std::isfinite(texel_size_))
        throw InputError(options_.sample_file.string(),
                         "has no positive texel size; give --sample-texel-size");
      btf_sample_ = std::make_unique<synth::BtfSample>(btf_);
      matched_ = btf_sample_.get();
    } else {
      sample_ = ReadSample(options_.sample_file);
      ptm_sample_ = std::make_unique<synth::PtmSample>(sample_.ptm);
      matched_ = ptm_sample_.get();
      if (!sample_.colour.empty()) {
        colour_sample_ = std::make_unique<synth::ColourSample>(sample_.colour);
        matched_ = colour_sample_.get();
      }
    }
    summary_.sample_kind = matched_->Name();
    summary_.seconds_sample = SecondsSince(start);
  }

  // Refused before anything is allocated (quilt::QuiltingBytes).
  void RequireSurfaceMemory(int features) const {
    RequireMemory(
        quilt::QuiltingBytes(mesh_, texel_size_, features), "the dense surface",
        options_.mesh_file.string() + " at a texel size of " + std::to_string(texel_size_));
  }

  // The sample's rotated copies (quilt::RotatedSample) must hold the smallest
  // work patch.
  void RefuseSampleSmallerThanWorkPatch() const {
    const int w = matched_->Width(), h = matched_->Height();
    const int side = static_cast<int>(std::floor(std::min(w, h) / std::numbers::sqrt2));
    const int smallest = 2 * options_.quilt.min_work_patch_levels + 1;
    if (side < std::max(smallest, 8))
      throw InputError(options_.sample_file.string(),
                       "is " + std::to_string(w) + " x " + std::to_string(h) +
                           " texels; turned, it leaves squares of " + std::to_string(side) +
                           ", smaller than the smallest work patch (" + std::to_string(smallest) +
                           " texels a side)");
  }

  // The sample's rotated copies the quilting keeps (8, each with its planes and
  // their spectra: quilt::RotatedSample).
  void RequireCopyMemory() const {
    const double side =
        std::floor(std::min(matched_->Width(), matched_->Height()) / std::numbers::sqrt2);
    RequireMemory(8 * side * side * (2.0 * matched_->NumFeatures() + 2) * 4 * 1.2,
                  "the sample's rotated copies", options_.sample_file.string());
  }

  void LayOut() {
    const auto start = std::chrono::steady_clock::now();
    // The face frames' x axes: the world direction laid onto each face, the
    // field the sample follows when no field file is given.
    geometry_ = synth::MakePatchGeometry(mesh_, texel_size_, 2, synth::TangentFrame::kSmoothField,
                                         options_.field_direction_in_world);
    layout_ = atlas::LayoutAtlases(mesh_, geometry_.patches, geometry_.unfoldings, texel_size_,
                                   options_.atlas, progress_);
    surface_ =
        quilt::DenseSurface::Build(layout_, geometry_.patches, geometry_.unfoldings, texel_size_);
    summary_.samples = surface_.size();
    summary_.links = surface_.links();
    summary_.chart_seam_links = surface_.chart_seam_links();
    summary_.seconds_layout = SecondsSince(start);
  }

  void Quilt() {
    result_ = quilt::QuiltSurface(surface_, layout_, *matched_, quilt_options_, progress_);
    summary_.stats = result_.stats;
    summary_.seconds_quilting = result_.stats.seconds;
  }

  // PTM atlases, or BTF atlases and their PTM preview as the model's atlases.
  void Bake() {
    const auto start = std::chrono::steady_clock::now();
    if (btf_sample_) {
      btf_atlases_ = quilt::BakeQuiltedBtfAtlases(surface_, result_, layout_, btf_,
                                                  options_.atlas.gutter, progress_);
      summary_.seconds_atlas = SecondsSince(start);
      const auto preview = std::chrono::steady_clock::now();
      ptms_ = atlas::PreviewPtms(btf_atlases_, btf_, progress_);
      summary_.seconds_preview = SecondsSince(preview);
      summary_.occupancy = btf_atlases_.occupancy;
    } else {
      atlas::Atlases atlases =
          quilt::BakeQuiltedAtlases(surface_, result_, layout_, geometry_.patches, *ptm_sample_,
                                    options_.atlas.gutter, progress_);
      ptms_ = std::move(atlases.ptms);
      summary_.occupancy = atlases.occupancy;
      summary_.seconds_atlas = SecondsSince(start);
    }
    summary_.atlases = ptms_.size();
    summary_.charts = static_cast<std::size_t>(layout_.num_charts);
  }

  void Write() {
    model::TexturedModel model;
    model.mesh = mesh_;
    model.atlases = ptms_;
    for (const atlas::FacePlacement& fp : layout_.faces) {
      model.face_atlas.push_back(fp.atlas);
      model.corner_px.push_back({fp.corners_px[0].cast<float>(), fp.corners_px[1].cast<float>(),
                                 fp.corners_px[2].cast<float>()});
    }
    nlohmann::json record = Record();
    std::optional<model::BtfModelFiles> files;
    if (btf_sample_) {
      files.emplace(btf_, btf_atlases_.sample_coords, btf_atlases_.colour_gain,
                    btf_atlases_.geometry);
      record["btf"] = files->Manifest();
    }
    model::WriteModelFolder(options_.out_dir, model, record, {}, [&](const fs::path& folder) {
      if (files) files->Write(folder);
      if (options_.write_report) WriteReport(model, folder);
    });
  }

  // report.html: the sample, the model from views around it beside flat
  // shading (no photos to compare with), a light sweep, the atlases, figures.
  void WriteReport(const model::TexturedModel& model, const fs::path& folder) {
    const auto start = std::chrono::steady_clock::now();
    report::ReportInputs report;
    report.title = "texlume synth --engine graphcut: " + options_.mesh_file.filename().string();
    report.intro =
        "The mesh covered with the material sample by graph-cut quilting on a dense resampling "
        "of its surface (paper 004 \u00a7III), without photos: nothing ties the texture to the "
        "object's own. Below, the model from four views around it, each under a light from "
        "above the camera's left, beside flat shading with the model's mean colour.";
    report.model = &model;
    ReportScene scene;
    scene.model = &model;
    scene.flat_albedo = MeanHeadOnColour(model);
    scene.sample = btf_sample_ ? nullptr : &sample_.ptm;
    scene.views = ViewsAroundMesh(mesh_, 4, 400, 300);
    report.views_heading = "Views around the model (no photos to compare with)";
    DrawReportPictures(scene, report, progress_);
    const quilt::QuiltStats& q = summary_.stats;
    report.facts = {
        {"sample", summary_.sample_kind + ", " + options_.sample_file.filename().string()},
        {"triangles", std::to_string(summary_.faces)},
        {"dense samples", std::to_string(summary_.samples) + " (" +
                              std::to_string(summary_.chart_seam_links) + " links across charts)"},
        {"patches", std::to_string(q.patches) + " (" + std::to_string(q.forced) +
                        " forced at the smallest work patch)"},
        {"seam cost per cut link", SeamText(q)},
        {"sample and atlas texel size", WorldLengthText(texel_size_, options_.mm_per_world_unit)},
        {"atlases", std::to_string(summary_.atlases) + " of " +
                        std::to_string(options_.atlas.atlas_size) + " texels, " +
                        std::to_string(summary_.charts) + " charts"}};
    for (const std::string& w : summary_.warnings) report.facts.emplace_back("warning", w);
    report.inputs = {{"mesh", options_.mesh_file}};
    if (!options_.BtfSample()) report.inputs.emplace_back("sample", options_.sample_file);
    report.view_folder = options_.out_dir.string();
    report.texel_size = texel_size_;
    report.mm_per_world_unit = options_.mm_per_world_unit;
    report.occupancy = summary_.occupancy;
    report.timings_s = {{"sample", summary_.seconds_sample},
                        {"layout", summary_.seconds_layout},
                        {"quilting", summary_.seconds_quilting},
                        {"atlas", summary_.seconds_atlas}};
    report.links = {
        {"model.glb", "model.glb"}, {"model.obj", "model.obj"}, {"manifest.json", "manifest.json"}};
    report::WriteReport(folder, report, progress_);
    summary_.seconds_report = SecondsSince(start);
  }

  std::string SeamText(const quilt::QuiltStats& q) const {
    const double share = quilt::SeamShare(q);
    char text[96];
    std::snprintf(text, sizeof text, "%.2f of a cut between unrelated texels (T_c %.2f)", share,
                  options_.quilt.seam_threshold);
    return text;
  }

  // The flat baseline's colour: the model's atlases lit head-on, averaged over
  // the texels that hold a value.
  static Eigen::Vector3f MeanHeadOnColour(const model::TexturedModel& model) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double count = 0;
    for (const ptm::Ptm& p : model.atlases)
      for (std::size_t t = 0; t < p.NumTexels(); ++t) {
        const Eigen::Vector3f c = p.Evaluate(t, 0.0, 0.0);
        if (c.isZero()) continue;
        sum += c.cast<double>();
        ++count;
      }
    return count > 0 ? Eigen::Vector3f((sum / count).cast<float>())
                     : Eigen::Vector3f::Constant(0.5f);
  }

  nlohmann::json Record() const {
    const quilt::QuiltStats& q = summary_.stats;
    nlohmann::json accepted = nlohmann::json::object();
    for (const auto& [levels, n] : q.accepted_at_levels) accepted[std::to_string(levels)] = n;
    const double per_link = q.cut_links ? q.seam_cost / static_cast<double>(q.cut_links) : 0.0;
    nlohmann::json settings = options_.ToJson();
    settings["sample_texel_size"] = texel_size_;  // a BTF's own when not given
    if (btf_sample_) settings["btf_components"] = btf_.Components();
    return {{"command", "synth"},
            {"inputs",
             {{"mesh", options_.mesh_file.string()}, {"sample", options_.sample_file.string()}}},
            {"settings", settings},
            {"summary",
             {{"sample_kind", summary_.sample_kind},
              {"faces", summary_.faces},
              {"dense_samples", summary_.samples},
              {"links", summary_.links},
              {"links_across_charts", summary_.chart_seam_links},
              {"patches", q.patches},
              {"accepted_at_work_patch_levels", accepted},
              {"forced_patches", q.forced},
              {"seam_cost_per_cut_link", per_link},
              {"unrelated_cut_cost", q.random_pair_cost},
              {"atlases", summary_.atlases},
              {"charts", summary_.charts},
              {"occupancy", summary_.occupancy}}},
            {"warnings", summary_.warnings},
            {"timings_s",
             {{"sample", summary_.seconds_sample},
              {"layout", summary_.seconds_layout},
              {"quilting", summary_.seconds_quilting},
              {"quilting_per_patch",
               summary_.seconds_quilting / std::max<double>(1.0, static_cast<double>(q.patches))},
              {"atlas", summary_.seconds_atlas},
              {"ptm_preview",
               btf_sample_ ? nlohmann::json(summary_.seconds_preview) : nlohmann::json(nullptr)}}}};
  }

  const QuiltJobOptions& options_;
  const ProgressCallback& progress_;
  quilt::QuiltOptions quilt_options_;  ///< the options', with the interpolated field
  mesh::TriangleMesh mesh_;
  double texel_size_ = 0;  ///< world units per sample texel (the BTF's own when not given)
  Sample sample_;
  btf::BtfFactorisation btf_;
  std::unique_ptr<synth::PtmSample> ptm_sample_;
  std::unique_ptr<synth::ColourSample> colour_sample_;
  std::unique_ptr<synth::BtfSample> btf_sample_;
  const synth::MaterialSample* matched_ = nullptr;  ///< the sample the quilting matches
  synth::PatchGeometry geometry_;
  atlas::AtlasLayout layout_;
  quilt::DenseSurface surface_;
  quilt::QuiltResult result_;
  atlas::BtfAtlases btf_atlases_;
  std::vector<ptm::Ptm> ptms_;  ///< the model's atlases (a BTF's preview)
  QuiltJobSummary summary_;
};

}  // namespace

QuiltJobSummary RunQuiltJob(const QuiltJobOptions& options, const ProgressCallback& progress) {
  options.Check();
  return QuiltJob(options, progress).Run();
}

}  // namespace texlume::pipeline
