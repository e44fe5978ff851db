#include "pipeline/btf_synth_job.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/errors.h"
#include "core/timing.h"
#include "model/baselines.h"
#include "model/btf_model.h"
#include "model/model_io.h"
#include "ptm/coefficient_space.h"
#include "ptm/exr_io.h"
#include "render/model_render.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;
void BtfSynthJobOptions::Check() const {
  job.CheckInputsAndLayout();
  if (btf.empty()) throw OptionError("synth --btf needs a BTF capture or factorisation folder");
  if (components < 1) throw OptionError("components must be >= 1");
  if (job.fill_unseen == FillUnseen::kGraphcut) job.fill_quilt.Check();
  if (!(synthesis.sample_texel_size >= 0.0))
    throw OptionError("sample texel size must be >= 0 (0: the capture's)");
  synth::BtfMeshSynthesisOptions resolved = synthesis;
  if (resolved.sample_texel_size == 0.0) resolved.sample_texel_size = 1.0;  // any valid size
  resolved.Check();
}

namespace {

// The BTF job's steps, each a method (RunBtfSynthJob).
class BtfSynthJob {
 public:
  BtfSynthJob(const BtfSynthJobOptions& options, const ProgressCallback& progress)
      : options_(options), job_(options.job), progress_(progress) {}

  BtfSynthJobSummary Run() {
    const auto start = std::chrono::steady_clock::now();
    pipeline::RefuseForeignModelFolder(job_.out_dir);
    AnnounceStep(progress_, "reading the inputs");
    inputs_ = pipeline::LoadSynthInputs(job_);
    AnnounceStep(progress_, "reading the BTF sample");
    LoadSample();
    Synthesize();
    if (synthesis_.rank_share_only) {  // its faces went to rank 0, which writes the model
      summary_.rank_share_only = true;
      return summary_;
    }
    LayOut();
    AnnounceStep(progress_, "writing the model folder");
    nlohmann::json record = Record();
    // The geometry maps baked per atlas texel, for export (docs/btf.md).
    const auto t = std::chrono::steady_clock::now();
    const model::BtfModelFiles btf_files(sample_, atlases_.sample_coords, atlases_.colour_gain,
                                         atlases_.geometry);
    record["btf"] = btf_files.Manifest();
    summary_.seconds_export = SecondsSince(t);
    record["timings_s"]["export_geometry"] = summary_.seconds_export;
    model::WriteModelFolder(job_.out_dir, model_, record, extra_images_,
                            [&](const fs::path& folder) { btf_files.Write(folder); });
    summary_.seconds_total = SecondsSince(start);
    return summary_;
  }

 private:
  // The sample: a factorisation as it is, or a capture factorised here; its
  // error table; the synthesis settings with its texel size; the mesh.
  void LoadSample() {
    const auto t = std::chrono::steady_clock::now();
    sample_ = btf::ReadOrFactoriseBtf(options_.btf, options_.components, progress_);
    summary_.seconds_factorise = SecondsSince(t);
    so_ = options_.synthesis;
    if (so_.sample_texel_size == 0.0) so_.sample_texel_size = sample_.texel_size;
    so_.Check();
    pipeline::PrepareSynthMesh(inputs_, job_, std::min(sample_.width, sample_.height),
                               so_.sample_texel_size, so_.strip, progress_);
    summary_.CountInputs(inputs_);
  }

  void Synthesize() {
    const std::optional<synth::FaceRegions> regions = pipeline::RegionsOfJob(job_, inputs_, so_);
    synthesis_ = synth::SynthesizeMeshBtf(inputs_.mesh, inputs_.reconstruction, inputs_.visibility,
                                          inputs_.photos, sample_, so_, progress_,
                                          regions ? &*regions : nullptr);
    if (synthesis_.rank_share_only) return;
    summary_.seconds_synthesis = synthesis_.seconds_synthesis;
    summary_.seconds_seams = synthesis_.seconds_seams;
    summary_.from_photos = synthesis_.num_from_photos;
    summary_.from_neighbours = synthesis_.num_from_neighbours;
    summary_.random = synthesis_.num_random;
    summary_.seam_edges = synthesis_.seam_edges;
    summary_.seam_cost_per_link = synthesis_.seam_cost_per_link;
    summary_.edge_cost_per_link = synthesis_.edge_cost_per_link;
    if (job_.fill_unseen == pipeline::FillUnseen::kGraphcut) FillUnseenFaces();
  }

  // The faces no photo placed, quilted by the graph-cut engine on the sample's
  // geometry maps (quilt/unseen_fill.h).
  void FillUnseenFaces() {
    AnnounceStep(progress_, "quilting the faces no photo sees (graph cut)");
    pipeline::RequireFillMemory(job_, inputs_.mesh, synthesis_.texel_size, sample_.Components());
    summary_.unseen_fill =
        quilt::FillUnseenFaces(inputs_.mesh, synthesis_, synth::BtfSample(sample_),
                               pipeline::UnseenFillOptionsOf(job_, so_.seed), progress_);
  }

  // The atlases, the PTM preview as the model's atlases, and the baselines
  // `texlume render` draws, as for PTM models.
  void LayOut() {
    auto t = std::chrono::steady_clock::now();
    atlases_ = atlas::BuildBtfAtlases(inputs_.mesh, synthesis_, sample_, job_.atlas, progress_);
    summary_.seconds_atlas = SecondsSince(t);
    summary_.atlases = atlases_.geometry.size();
    summary_.charts = static_cast<std::size_t>(atlases_.layout.num_charts);
    summary_.chart_flattening = job_.atlas.mode == atlas::AtlasMode::kCharts
                                    ? atlas::ChartFlatteningName(atlases_.layout.flattening)
                                    : "none";
    summary_.occupancy = atlases_.occupancy;
    t = std::chrono::steady_clock::now();
    model_ = pipeline::TexturedModelOf(inputs_, atlas::PreviewPtms(atlases_, sample_, progress_),
                                       atlases_.layout.faces);
    model_.light_response = synthesis_.light_response;
    summary_.seconds_preview = SecondsSince(t);
    baked_ =
        render::BakePhotoTextures(model_, inputs_.reconstruction, inputs_.visibility,
                                  inputs_.photos, synthesis_.photo_gains, synthesis_.white_balance);
    flat_albedo_ = render::MeanAlbedoFromPhotos(inputs_.mesh, inputs_.reconstruction,
                                                inputs_.visibility, inputs_.photos,
                                                synthesis_.photo_gains, synthesis_.white_balance);
  }

  nlohmann::json Settings() const {
    nlohmann::json settings = {{"sample_texel_size", so_.sample_texel_size},
                               {"world_unit_mm", WorldUnitJson(job_.mm_per_world_unit)},
                               {"components", sample_.Components()},
                               {"strip", so_.strip},
                               {"seam_band", so_.seam_band},
                               {"top_k", so_.top_k},
                               {"search", synth::PlacementSearchName(so_.search)},
                               {"search_candidates", so_.search_candidates},
                               {"photometry_faces", so_.photometry_faces},
                               {"max_views", so_.max_views},
                               {"tangent_frame", synth::TangentFrameName(so_.tangent_frame)},
                               {"tolerance", so_.tolerance},
                               {"photo_correction", so_.photo_correction},
                               {"correction_noise", so_.correction_noise},
                               {"correction_sigma", so_.correction_sigma},
                               {"light_response", so_.light_response},
                               {"white_balance", so_.white_balance},
                               {"photo_blur", so_.photo_blur},
                               {"seed", so_.seed},
                               {"horizon_elevation_deg", ptm::kHorizonElevationDeg}};
    settings.update(pipeline::FillUnseenSettingsJson(job_));
    settings.update(pipeline::AtlasSettingsJson(job_.atlas));
    return settings;
  }

  nlohmann::json Summary() const {
    const BtfSynthJobSummary& s = summary_;
    nlohmann::json summary = s.ToJson();
    summary.update({{"seam_edges", s.seam_edges},
                    {"seam_cost_per_link", s.seam_cost_per_link},
                    {"straight_edge_cost_per_link", s.edge_cost_per_link},
                    {"photo_rms_quilted", synthesis_.photo_rms_quilted},
                    {"photo_rms_corrected", synthesis_.photo_rms_corrected}});
    summary.update(pipeline::EngineSummaryJson(synthesis_));
    if (job_.fill_unseen == pipeline::FillUnseen::kGraphcut)
      summary["unseen_fill"] = pipeline::UnseenFillJson(s.unseen_fill);
    return summary;
  }

  nlohmann::json Record() {
    nlohmann::json record;
    record["command"] = "synth --btf";
    record["inputs"] = job_.InputsJson();
    record["inputs"]["btf"] = options_.btf.string();
    record["settings"] = Settings();
    record["summary"] = Summary();
    record["warnings"] = summary_.warnings;
    extra_images_ = model::RecordBaselines(flat_albedo_, baked_, record);
    const BtfSynthJobSummary& s = summary_;
    record["timings_s"] = {
        {"load", inputs_.seconds_load},
        {"visibility", inputs_.seconds_visibility},
        {"factorise", s.seconds_factorise},
        {"synthesis", s.seconds_synthesis},
        {"seams", s.seconds_seams},
        {"unseen_fill", s.unseen_fill.seconds},
        {"atlas", s.seconds_atlas},
        {"ptm_preview", s.seconds_preview},
        {"synthesis_per_triangle", (s.seconds_synthesis + s.seconds_seams) /
                                       static_cast<double>(std::max<std::size_t>(1, s.faces))}};
    if (const nlohmann::json d = pipeline::RanksJson(synthesis_, std::nullopt); !d.is_null())
      record["distributed"] = d;
    return record;
  }

  const BtfSynthJobOptions& options_;
  const pipeline::SynthJobOptions& job_;
  const ProgressCallback& progress_;
  BtfSynthJobSummary summary_;
  pipeline::SynthInputs inputs_;
  btf::BtfFactorisation sample_;
  synth::BtfMeshSynthesisOptions so_;
  synth::BtfMeshSynthesis synthesis_;
  atlas::BtfAtlases atlases_;
  model::TexturedModel model_;
  std::vector<cv::Mat> baked_;
  Eigen::Vector3f flat_albedo_ = Eigen::Vector3f::Constant(0.5f);
  std::vector<std::pair<std::string, cv::Mat>> extra_images_;
};

}  // namespace

BtfSynthJobSummary RunBtfSynthJob(const BtfSynthJobOptions& options,
                                  const ProgressCallback& progress) {
  options.Check();
  return BtfSynthJob(options, progress).Run();
}

}  // namespace texlume::pipeline
