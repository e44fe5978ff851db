#include "pipeline/quilt_job.h"

#include <Eigen/Eigenvalues>
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
#include "quilt/image_term.h"
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
  CheckPhotos();
  atlas.Check();
  CheckWorldUnit(mm_per_world_unit);
}

void QuiltJobOptions::CheckPhotos() const {
  const int given = !model_dir.empty() + !images_dir.empty() + !lights_file.empty();
  if (given != 0 && given != 3)
    throw OptionError(
        "synth --engine graphcut follows photos with --model, --images and --lights together");
  if (!Photos()) return;
  synth::TriangleEngineOptions engine = photo_engine;
  engine.sample_texel_size = 1.0;  // the job's, checked above
  engine.Check();
  visibility.Check();
  if (photo_engine.tangent_frame == synth::TangentFrame::kFirstEdge)
    throw OptionError(
        "--tangent-frame first-edge gives no field to quilt along; give auto or photos, or "
        "--tangent-field");
  if (photo_engine.tangent_frame == synth::TangentFrame::kPhotos &&
      (!field_file.empty() || quilt.random_orientation))
    throw OptionError(
        "--tangent-frame photos is a field: give it, --field or --orientation random, not two");
}

nlohmann::json QuiltJobOptions::PhotosJson() const {
  if (!Photos()) return nullptr;
  return {{"top_k", photo_engine.top_k},
          {"all_views", photo_engine.all_views},
          {"max_views", photo_engine.max_views},
          {"min_photo_pixels", photo_engine.min_photo_pixels},
          {"tangent_frame", synth::TangentFrameName(photo_engine.tangent_frame)},
          {"light_response", photo_engine.light_response},
          {"view_term", photo_engine.view_term},
          {"white_balance", photo_engine.white_balance},
          {"photo_blur", photo_engine.photo_blur},
          {"max_buffer_size", visibility.max_buffer_dimension}};
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
      {"photos", PhotosJson()},
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
    CalibratePhotos();
    Quilt();
    Bake();
    AnnounceStep(progress_, "writing the model folder");
    Write();
    summary_.seconds_total = SecondsSince(start);
    return summary_;
  }

 private:
  void Load() {
    if (options_.Photos()) {
      LoadPhotos();
    } else {
      mesh::LoadedMesh loaded = mesh::LoadMesh(options_.mesh_file);
      for (const std::string& problem : loaded.report.Problems())
        summary_.warnings.push_back(options_.mesh_file.string() + ": " + problem);
      inputs_.mesh = std::move(loaded.mesh);
    }
    if (inputs_.mesh.faces.empty())
      throw InputError(options_.mesh_file.string(), "has no triangles");
    summary_.faces = inputs_.mesh.faces.size();
    texel_size_ = options_.sample_texel_size;
    if (texel_size_ > 0) RequireSurfaceMemory(3);  // before the sample is read, at least
    LoadSample();
    RefuseSampleLargerThanMesh(inputs_.mesh, texel_size_, options_.mesh_file);
    RequireSurfaceMemory(matched_->NumFeatures());
    RefuseSampleSmallerThanWorkPatch();
    RequireCopyMemory();
    if (!options_.field_file.empty())
      quilt_options_.field_in_world = quilt::InterpolateField(
          inputs_.mesh, quilt::ReadFieldFile(options_.field_file, inputs_.mesh));
    if (options_.Photos()) ComputeVisibility();
  }

  // The COLMAP model, the lights, the mesh (in the model's frame) and the
  // photos, as the main job reads them (LoadSynthInputs).
  SynthJobOptions PhotoInputs() const {
    SynthJobOptions job;
    job.model_dir = options_.model_dir;
    job.images_dir = options_.images_dir;
    job.lights_file = options_.lights_file;
    job.mesh_file = options_.mesh_file;
    job.visibility = options_.visibility;
    job.max_subdivisions = 0;  // quilting takes triangles of any size
    return job;
  }

  void LoadPhotos() {
    const auto start = std::chrono::steady_clock::now();
    AnnounceStep(progress_, "reading the photos");
    inputs_ = LoadSynthInputs(PhotoInputs());
    summary_.warnings.insert(summary_.warnings.end(), inputs_.warnings.begin(),
                             inputs_.warnings.end());
    summary_.photos_used = inputs_.photos.size();
    summary_.seconds_photos = SecondsSince(start);
  }

  // Which faces each photo sees (refused when most are seen by none: a mesh
  // in another frame).
  void ComputeVisibility() {
    const auto start = std::chrono::steady_clock::now();
    AnnounceStep(progress_, "visibility");
    PrepareSynthMesh(inputs_, PhotoInputs(), std::numeric_limits<int>::max(), texel_size_, 2,
                     progress_);
    summary_.seconds_photos += SecondsSince(start);
  }

  // The photos calibrated against the sample (gains, white balance, light
  // response, blur: synth::TriangleEngine::Prepare), and the frames that give
  // the field when the photos orient the sample.
  void CalibratePhotos() {
    if (!options_.Photos()) return;
    const auto start = std::chrono::steady_clock::now();
    AnnounceStep(progress_, "calibrating the photos against the sample");
    engine_options_ = options_.photo_engine;
    engine_options_.sample_texel_size = texel_size_;
    engine_options_.field_direction_in_world = options_.field_direction_in_world;
    engine_options_.strip = 2;  // as the layout's patches: the calibration rectifies faces whole
    const bool field_given = !options_.field_file.empty() || options_.quilt.random_orientation;
    if (field_given) engine_options_.tangent_frame = synth::TangentFrame::kSmoothField;
    MakeCalibrationMesh();
    engine_ = std::make_unique<synth::TriangleEngine>(CalibrationMesh(), inputs_.reconstruction,
                                                      CalibrationVisibility(), inputs_.photos,
                                                      *matched_, engine_options_, nullptr);
    const synth::TriangleSynthesis& photometry = engine_->Prepare(progress_);
    if (!field_given && photometry.tangent_frame == synth::TangentFrame::kPhotos)
      for (std::size_t f = 0; f < inputs_.mesh.faces.size(); ++f)
        quilt_options_.field_in_world.push_back(FieldOfFace(f, photometry));
    light_response_ = photometry.light_response;
    summary_.photo_calibration = EngineSummaryJson(photometry);
    summary_.photo_calibration["mesh_subdivisions"] = calibration_subdivisions_;
    summary_.seconds_photometry = SecondsSince(start);
  }

  // The calibration rectifies whole faces into the sample: faces whose patch
  // does not fit it are left out of it. When some do not fit, it runs on a
  // midpoint subdivision of the mesh (with its own visibility), as the main job
  // subdivides its mesh; the quilt keeps the mesh as given.
  void MakeCalibrationMesh() {
    const int side = std::min(matched_->Width(), matched_->Height());
    const auto fits = [&](const mesh::TriangleMesh& m) {
      return LargestPatchSide(m, texel_size_, engine_options_.strip) <= side;
    };
    calibration_subdivisions_ = 0;
    if (fits(inputs_.mesh)) return;
    while (calibration_subdivisions_ < kMostCalibrationSubdivisions &&
           CalibrationMesh().faces.size() * 4 <= kMostCalibrationFaces &&
           !fits(CalibrationMesh())) {
      calibration_mesh_ = mesh::SubdivideMidpoint(CalibrationMesh());
      ++calibration_subdivisions_;
    }
    const bool all_fit = fits(CalibrationMesh());
    if (calibration_subdivisions_ == 0) {
      summary_.warnings.push_back(
          "some triangles do not fit the sample, and the photo calibration leaves them out (the "
          "mesh has too many faces to subdivide for it)");
      return;
    }
    calibration_visibility_ = sfm::ComputeVisibility(calibration_mesh_, inputs_.reconstruction,
                                                     PhotoInputs().visibility, progress_);
    summary_.warnings.push_back("calibrated the photos on the mesh subdivided " +
                                std::to_string(calibration_subdivisions_) +
                                " time(s), so that its triangles fit the sample (the quilt "
                                "keeps the mesh)" +
                                (all_fit ? std::string()
                                         : "; some still do not fit, and the calibration "
                                           "leaves them out"));
  }
  const mesh::TriangleMesh& CalibrationMesh() const {
    return calibration_subdivisions_ ? calibration_mesh_ : inputs_.mesh;
  }
  const sfm::VisibilityResult& CalibrationVisibility() const {
    return calibration_subdivisions_ ? calibration_visibility_ : inputs_.visibility;
  }
  // The line field of face f from the calibration's frames: mesh::SubdivideMidpoint
  // makes faces 4f to 4f + 3 of face f, so after k subdivisions its faces are
  // [f 4^k, (f + 1) 4^k). Their x axes, as lines (d and -d alike), averaged:
  // the main eigenvector of the sum of d d^T, signed as the first one.
  Eigen::Vector3d FieldOfFace(std::size_t f, const synth::TriangleSynthesis& photometry) const {
    if (calibration_subdivisions_ == 0) return photometry.patches[f].frame.x_axis;
    const std::size_t children = std::size_t{1} << (2 * calibration_subdivisions_);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (std::size_t c = f * children; c < (f + 1) * children; ++c) {
      const Eigen::Vector3d& d = photometry.patches[c].frame.x_axis;
      scatter += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    Eigen::Vector3d line = eigen.eigenvectors().col(2);
    const Eigen::Vector3d& first = photometry.patches[f * children].frame.x_axis;
    return line.dot(first) < 0 ? Eigen::Vector3d(-line) : line;
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
        quilt::QuiltingBytes(inputs_.mesh, texel_size_, features), "the dense surface",
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
  // their spectra: quilt::RotatedSample) and, with photos, what the image term
  // keeps (quilt::PhotoImageTerm): the sample's relight planes at full size
  // (MaterialSample::Reduced(0)), the sample relit (3 planes, while a copy is
  // relit) and, per view of one seed face, a relit copy (3 planes and their
  // energy).
  void RequireCopyMemory() const {
    const double side =
        std::floor(std::min(matched_->Width(), matched_->Height()) / std::numbers::sqrt2);
    double bytes = 8 * side * side * (2.0 * matched_->NumFeatures() + 2) * 4 * 1.2;
    if (options_.Photos()) {
      const synth::TriangleEngineOptions& e = options_.photo_engine;
      const double views = e.all_views ? std::max(e.max_views, 1) : 1;
      const double sample_texels = static_cast<double>(matched_->Width()) * matched_->Height();
      bytes += ((matched_->NumRelightPlanes() + 3) * sample_texels + views * 4 * side * side) * 4;
    }
    RequireMemory(bytes, "the sample's rotated copies", options_.sample_file.string());
  }

  void LayOut() {
    const auto start = std::chrono::steady_clock::now();
    // The face frames' x axes: the world direction laid onto each face, the
    // field the sample follows when no field file is given.
    geometry_ =
        synth::MakePatchGeometry(inputs_.mesh, texel_size_, 2, synth::TangentFrame::kSmoothField,
                                 options_.field_direction_in_world);
    layout_ = atlas::LayoutAtlases(inputs_.mesh, geometry_.patches, geometry_.unfoldings,
                                   texel_size_, options_.atlas, progress_);
    surface_ = quilt::DenseSurface::Build(inputs_.mesh, layout_, geometry_.patches,
                                          geometry_.unfoldings, texel_size_);
    summary_.samples = surface_.size();
    summary_.links = surface_.links();
    summary_.chart_seam_links = surface_.chart_seam_links();
    summary_.seconds_layout = SecondsSince(start);
  }

  void Quilt() {
    std::optional<quilt::PhotoImageTerm> image_term;
    if (engine_) {
      evidence_.emplace(quilt::PhotoEvidence{inputs_.reconstruction, inputs_.visibility,
                                             inputs_.photos, engine_->result()});
      const synth::TriangleEngineOptions& e = engine_options_;
      image_term.emplace(surface_, layout_, *matched_, *evidence_,
                         quilt::ImageTermOptions{e.all_views, e.max_views, e.min_photo_pixels});
      quilt_options_.image_top_k = e.top_k;
    }
    result_ = quilt::QuiltSurface(surface_, layout_, *matched_, quilt_options_, progress_, nullptr,
                                  image_term ? &*image_term : nullptr);
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
    // Without photos the reconstruction has no cameras: the model is not turned.
    model::TexturedModel model = TexturedModelOf(inputs_, ptms_, layout_.faces);
    model.light_response = light_response_;  // as the photos showed it (the identity without)
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
        options_.Photos()
            ? "The mesh covered with the material sample by graph-cut quilting on a dense "
              "resampling of its surface (paper 004 \u00a7III), each patch placed where the "
              "sample relit under the photos' lights agrees best with the photos (paper 003's "
              "image term). Below, the model from some of the photos' views under their lights "
              "beside the photo (divided by its estimated exposure) and flat shading."
            : "The mesh covered with the material sample by graph-cut quilting on a dense "
              "resampling of its surface (paper 004 \u00a7III), without photos: nothing ties the "
              "texture to the object's own. Below, the model from four views around it, each "
              "under a light from above the camera's left, beside flat shading with the model's "
              "mean colour.";
    report.model = &model;
    ReportScene scene;
    scene.model = &model;
    scene.flat_albedo = MeanHeadOnColour(model);
    scene.sample = btf_sample_ ? nullptr : &sample_.ptm;
    if (engine_) {
      AddPhotoViews(inputs_, options_.images_dir, engine_->result().photo_gains, report, scene);
    } else {
      scene.views = ViewsAroundMesh(inputs_.mesh, 4, 400, 300);
      report.views_heading = "Views around the model (no photos to compare with)";
    }
    DrawReportPictures(scene, report, progress_);
    const quilt::QuiltStats& q = summary_.stats;
    report.facts = {
        {"sample", summary_.sample_kind + ", " + options_.sample_file.filename().string()},
        {"triangles", std::to_string(summary_.faces)},
        {"dense samples", std::to_string(summary_.samples) + " (" +
                              std::to_string(summary_.chart_seam_links) + " links across charts)"},
        {"patches", std::to_string(q.patches) + " (" + std::to_string(q.forced) +
                        " forced at the smallest work patch" + PhotoPatchesText() + ")"},
        {"seam cost per cut link", SeamText(q)},
        {"sample and atlas texel size", WorldLengthText(texel_size_, options_.mm_per_world_unit)},
        {"atlases", std::to_string(summary_.atlases) + " of " +
                        std::to_string(options_.atlas.atlas_size) + " texels, " +
                        std::to_string(summary_.charts) + " charts"}};
    for (const std::string& w : summary_.warnings) report.facts.emplace_back("warning", w);
    report.inputs = {{"mesh", options_.mesh_file}};
    if (engine_) report.inputs = InputFiles(PhotoInputs(), inputs_.model_folder);
    if (!options_.BtfSample()) report.inputs.emplace_back("sample", options_.sample_file);
    report.view_folder = options_.out_dir.string();
    report.texel_size = texel_size_;
    report.mm_per_world_unit = options_.mm_per_world_unit;
    report.occupancy = summary_.occupancy;
    report.timings_s = {{"sample", summary_.seconds_sample},
                        {"layout", summary_.seconds_layout},
                        {"quilting", summary_.seconds_quilting},
                        {"atlas", summary_.seconds_atlas}};
    if (engine_)
      report.timings_s.insert(report.timings_s.begin() + 1,
                              {{"photos and visibility", summary_.seconds_photos},
                               {"photo calibration", summary_.seconds_photometry}});
    report.links = {
        {"model.glb", "model.glb"}, {"model.obj", "model.obj"}, {"manifest.json", "manifest.json"}};
    report::WriteReport(folder, report, progress_);
    summary_.seconds_report = SecondsSince(start);
  }

  std::string PhotoPatchesText() const {
    if (!engine_) return "";
    return ", " + std::to_string(summary_.stats.photo_patches) + " placed by " +
           std::to_string(summary_.photos_used) + " photos";
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
    nlohmann::json inputs = {{"mesh", options_.mesh_file.string()},
                             {"sample", options_.sample_file.string()}};
    if (options_.Photos()) inputs.update(PhotoInputs().InputsJson());
    return {{"command", "synth"},
            {"inputs", inputs},
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
              {"photos_used", summary_.photos_used},
              {"patches_placed_by_photos", q.photo_patches},
              {"photos", summary_.photo_calibration},
              {"seam_cost_per_cut_link", per_link},
              {"unrelated_cut_cost", q.random_pair_cost},
              {"atlases", summary_.atlases},
              {"charts", summary_.charts},
              {"occupancy", summary_.occupancy}}},
            {"warnings", summary_.warnings},
            {"timings_s",
             {{"sample", summary_.seconds_sample},
              {"photos_and_visibility", summary_.seconds_photos},
              {"layout", summary_.seconds_layout},
              {"photo_calibration", summary_.seconds_photometry},
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
  /// The mesh; with photos also the COLMAP model, the photos and visibility.
  SynthInputs inputs_;
  synth::TriangleEngineOptions engine_options_;
  std::unique_ptr<synth::TriangleEngine> engine_;  ///< with photos: their calibration
  ptm::LightResponse light_response_;              ///< theirs, for the model
  /// With photos whose calibration needs smaller faces: the mesh subdivided.
  static constexpr int kMostCalibrationSubdivisions = 6;
  static constexpr std::size_t kMostCalibrationFaces = std::size_t{1} << 20;
  int calibration_subdivisions_ = 0;
  mesh::TriangleMesh calibration_mesh_;
  sfm::VisibilityResult calibration_visibility_;
  std::optional<quilt::PhotoEvidence> evidence_;
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
