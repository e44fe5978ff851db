#include "pipeline/quilt_job.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "core/timing.h"
#include "mesh/mesh.h"
#include "model/model_io.h"
#include "pipeline/synth_job.h"
#include "quilt/quilt_atlases.h"
#include "quilt/vector_field.h"
#include "synth/colour_sample.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;

void QuiltJobOptions::Check() const {
  for (const auto& [path, what] :
       {std::pair{&mesh_file, "--mesh"}, std::pair{&sample_file, "--sample"},
        std::pair{&out_dir, "--out"}})
    if (path->empty()) throw OptionError(std::string("synth --engine graphcut needs ") + what);
  if (!(sample_texel_size > 0.0) || !std::isfinite(sample_texel_size))
    throw OptionError("synth --engine graphcut needs --sample-texel-size > 0");
  quilt.Check();
  if (quilt.random_orientation && !field_file.empty())
    throw OptionError("give --field or --orientation random, not both");
  if (!field_direction_in_world.allFinite() || !(field_direction_in_world.norm() > 0))
    throw OptionError("--tangent-field must be a non-zero direction");
  atlas.Check();
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
      {"max_chart_stretch", atlas.max_chart_stretch}};
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
    RefuseSampleLargerThanMesh(mesh_, options_.sample_texel_size, options_.mesh_file);
    // Per dense sample: lookup, patch, features, links, index: about 64 bytes
    // plus 4 per feature; remembered seams (Kwatra's old seams: two feature
    // vectors and a hash node, on at most about one link in two); the stretch
    // of the charts adds up to 1.25^2.
    const std::vector<double> areas = mesh::FaceAreas(mesh_);
    const double area = std::accumulate(areas.begin(), areas.end(), 0.0);
    const double samples = 1.6 * area / std::pow(options_.sample_texel_size, 2);
    RequireMemory(samples * (64 + 4 * 18 + 0.5 * (2 * 4 * 18 + 96)), "the dense surface",
                  options_.mesh_file.string() + " at a texel size of " +
                      std::to_string(options_.sample_texel_size));
    if (!options_.field_file.empty())
      quilt_options_.field_in_world =
          quilt::InterpolateField(mesh_, quilt::ReadFieldFile(options_.field_file, mesh_));
    sample_ = ReadSample(options_.sample_file);
    RefuseSampleSmallerThanWorkPatch();
    RequireCopyMemory();
    ptm_sample_ = std::make_unique<synth::PtmSample>(sample_.ptm);
    if (!sample_.colour.empty())
      colour_sample_ = std::make_unique<synth::ColourSample>(sample_.colour);
    summary_.faces = mesh_.faces.size();
  }

  // The sample's rotated copies (quilt::RotatedSample) must hold the smallest
  // work patch.
  void RefuseSampleSmallerThanWorkPatch() const {
    const int side = static_cast<int>(
        std::floor(std::min(sample_.ptm.width, sample_.ptm.height) / std::numbers::sqrt2));
    const int smallest = 2 * options_.quilt.min_work_patch_levels + 1;
    if (side < std::max(smallest, 8))
      throw InputError(options_.sample_file.string(),
                       "is " + std::to_string(sample_.ptm.width) + " x " +
                           std::to_string(sample_.ptm.height) +
                           " texels; turned, it leaves squares of " + std::to_string(side) +
                           ", smaller than the smallest work patch (" + std::to_string(smallest) +
                           " texels a side)");
  }

  // The sample's rotated copies the quilting keeps (8, each with its planes and
  // their spectra: quilt::RotatedSample).
  void RequireCopyMemory() const {
    const double side =
        std::floor(std::min(sample_.ptm.width, sample_.ptm.height) / std::numbers::sqrt2);
    const double features = sample_.colour.empty() ? 18.0 : 3.0;
    RequireMemory(8 * side * side * (2 * features + 2) * 4 * 1.2, "the sample's rotated copies",
                  options_.sample_file.string());
  }

  void LayOut() {
    const auto start = std::chrono::steady_clock::now();
    // The face frames' x axes: the world direction laid onto each face, the
    // field the sample follows when no field file is given.
    geometry_ = synth::MakePatchGeometry(mesh_, options_.sample_texel_size, 2,
                                         synth::TangentFrame::kSmoothField,
                                         options_.field_direction_in_world);
    layout_ = atlas::LayoutAtlases(mesh_, geometry_.patches, geometry_.unfoldings,
                                   options_.sample_texel_size, options_.atlas, progress_);
    surface_ = quilt::DenseSurface::Build(layout_, geometry_.patches, geometry_.unfoldings,
                                          options_.sample_texel_size);
    summary_.samples = surface_.size();
    summary_.links = surface_.links();
    summary_.chart_seam_links = surface_.chart_seam_links();
    summary_.seconds_layout = SecondsSince(start);
  }

  void Quilt() {
    const synth::MaterialSample& matched =
        colour_sample_ ? static_cast<const synth::MaterialSample&>(*colour_sample_) : *ptm_sample_;
    result_ = quilt::QuiltSurface(surface_, layout_, matched, quilt_options_, progress_);
    summary_.stats = result_.stats;
    summary_.seconds_quilting = result_.stats.seconds;
  }

  void Bake() {
    atlases_ = quilt::BakeQuiltedAtlases(surface_, result_, layout_, geometry_.patches,
                                         *ptm_sample_, options_.atlas.gutter, progress_);
    summary_.atlases = atlases_.ptms.size();
    summary_.charts = static_cast<std::size_t>(atlases_.num_charts);
    summary_.occupancy = atlases_.occupancy;
    summary_.seconds_atlas = atlases_.seconds;
  }

  void Write() {
    model::TexturedModel model;
    model.mesh = mesh_;
    model.atlases = atlases_.ptms;
    for (const atlas::FacePlacement& fp : atlases_.faces) {
      model.face_atlas.push_back(fp.atlas);
      model.corner_px.push_back({fp.corners_px[0].cast<float>(), fp.corners_px[1].cast<float>(),
                                 fp.corners_px[2].cast<float>()});
    }
    model::WriteModelFolder(options_.out_dir, model, Record());
  }

  nlohmann::json Record() const {
    const quilt::QuiltStats& q = summary_.stats;
    nlohmann::json accepted = nlohmann::json::object();
    for (const auto& [levels, n] : q.accepted_at_levels) accepted[std::to_string(levels)] = n;
    const double per_link = q.cut_links ? q.seam_cost / static_cast<double>(q.cut_links) : 0.0;
    return {{"command", "synth"},
            {"inputs",
             {{"mesh", options_.mesh_file.string()}, {"sample", options_.sample_file.string()}}},
            {"settings", options_.ToJson()},
            {"summary",
             {{"faces", summary_.faces},
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
             {{"layout", summary_.seconds_layout},
              {"quilting", summary_.seconds_quilting},
              {"quilting_per_patch",
               summary_.seconds_quilting / std::max<double>(1.0, static_cast<double>(q.patches))},
              {"atlas", summary_.seconds_atlas}}}};
  }

  const QuiltJobOptions& options_;
  const ProgressCallback& progress_;
  quilt::QuiltOptions quilt_options_;  ///< the options', with the interpolated field
  mesh::TriangleMesh mesh_;
  Sample sample_;
  std::unique_ptr<synth::PtmSample> ptm_sample_;
  std::unique_ptr<synth::ColourSample> colour_sample_;
  synth::PatchGeometry geometry_;
  atlas::AtlasLayout layout_;
  quilt::DenseSurface surface_;
  quilt::QuiltResult result_;
  atlas::Atlases atlases_;
  QuiltJobSummary summary_;
};

}  // namespace

QuiltJobSummary RunQuiltJob(const QuiltJobOptions& options, const ProgressCallback& progress) {
  options.Check();
  return QuiltJob(options, progress).Run();
}

}  // namespace texlume::pipeline
