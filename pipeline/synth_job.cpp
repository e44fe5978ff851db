#include "pipeline/synth_job.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/memory_budget.h"
#include "core/partial_output.h"
#include "core/timing.h"
#include "core/units.h"
#include "mesh/mesh.h"
#include "model/baselines.h"
#include "pipeline/report_pictures.h"
#include "pipeline/sample_shadowing.h"
#include "ptm/ptm_io.h"
#include "render/model_render.h"
#include "report/report.h"
#include "sfm/alignment.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"
#include "synth/colour_sample.h"

namespace texlume::pipeline {
namespace fs = std::filesystem;
namespace {

// The fewest sample texels across the mesh's bounding box for a texture to mean
// anything: a larger texel size is a texel size in other units than the mesh's.
constexpr double kMinTexelsAcrossMesh = 4.0;

// Mean prior shrink over the photo-corrected patches (null when none was).
nlohmann::json MeanPriorShrink(const synth::MeshSynthesis& synthesis) {
  double sum = 0.0;
  int n = 0;
  for (const synth::TrianglePatch& p : synthesis.patches)
    if (p.prior_shrink >= 0.0) sum += p.prior_shrink, ++n;
  return n ? nlohmann::json(sum / n) : nlohmann::json(nullptr);
}

// The colour engine's settings from the PTM job's: the engine's, and the
// per-channel factors (off with --correction-iterations 0, as the PTM pass).
synth::ColourSynthesisOptions ColourOptions(const synth::MeshSynthesisOptions& ptm) {
  synth::ColourSynthesisOptions colour;
  static_cast<synth::TriangleEngineOptions&>(colour) = ptm;
  colour.photo_correction = ptm.correction_iterations > 0;
  colour.correction_noise = ptm.correction_noise;
  colour.correction_sigma = ptm.correction_sigma;
  return colour;
}

// The photos the job holds at once (float RGB and a luminance plane: 16 bytes a
// pixel), against the memory limit.
// The photos' cache (core/photo_cache.h): `--photo-cache`, or half the memory
// limit; never less than the minimum working set, the photos one face is
// constrained by (max_views of the largest), which the memory limit must hold.
std::uint64_t PhotoCacheBudget(const SynthJobOptions& options, std::uint64_t largest_photo_bytes,
                               std::uint64_t all_photos_bytes) {
  const std::uint64_t minimum =
      static_cast<std::uint64_t>(std::max(1, options.synthesis.max_views)) * largest_photo_bytes;
  RequireMemory(static_cast<double>(minimum),
                "the decoded photos one face is constrained by (" +
                    std::to_string(options.synthesis.max_views) + " of " +
                    MemorySizeText(static_cast<double>(largest_photo_bytes)) + ")",
                options.images_dir.string());
  if (options.photo_cache_bytes > 0 && options.photo_cache_bytes < minimum)
    throw OptionError("--photo-cache " +
                      MemorySizeText(static_cast<double>(options.photo_cache_bytes)) +
                      " cannot hold the " + std::to_string(options.synthesis.max_views) +
                      " photos one face is constrained by (" +
                      MemorySizeText(static_cast<double>(minimum)) + "); give at least that");
  const std::uint64_t budget =
      options.photo_cache_bytes > 0 ? options.photo_cache_bytes : MemoryLimitBytes() / 2;
  return std::min(all_photos_bytes, std::max(budget, minimum));
}

}  // namespace

void RefuseSampleLargerThanMesh(const mesh::TriangleMesh& mesh, double sample_texel_size,
                                const fs::path& mesh_path) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double diagonal = mesh.vertices.empty() ? 0.0 : (hi - lo).norm();
  if (!(diagonal >= kMinTexelsAcrossMesh * sample_texel_size)) {
    throw OptionError("the sample's texel size (" + std::to_string(sample_texel_size) +
                      " world units) is not small against the mesh " + mesh_path.string() +
                      " (diagonal " + std::to_string(diagonal) + ", fewer than " +
                      std::to_string(static_cast<int>(kMinTexelsAcrossMesh)) +
                      " texels across it); give --sample-texel-size in the mesh's units");
  }
}

bool IsColourImage(const fs::path& path) {
  const std::string ext = LowerCaseExtension(path);
  if (ext == ".ptm") return false;
  if (ext == ".exr") return ImageReader(path).channels() <= 4;  // a PTM EXR has 9 or 18
  return true;
}

Sample ReadSample(const fs::path& path) {
  Sample sample;
  if (!IsColourImage(path)) {
    sample.ptm = ptm::ReadPtmAnyFormat(path);
    return sample;
  }
  sample.colour = ReadPhotoRgb(path);
  sample.ptm = synth::LambertianPtm(sample.colour);
  return sample;
}

std::vector<std::pair<std::string, fs::path>> InputFiles(const SynthJobOptions& options,
                                                         const fs::path& model) {
  std::vector<std::pair<std::string, fs::path>> files;
  const std::string ext =
      sfm::DetectModelFormat(model) == sfm::ModelFormat::kBinary ? ".bin" : ".txt";
  for (const char* stem : {"cameras", "images", "points3D"})
    files.emplace_back("COLMAP " + std::string(stem), model / (stem + ext));
  files.emplace_back("lights", options.lights_file);
  files.emplace_back("mesh", options.mesh_file);
  if (!options.sample_file.empty()) files.emplace_back("sample", options.sample_file);
  if (!options.sample_horizon_file.empty())
    files.emplace_back("sample horizon", options.sample_horizon_file);
  return files;
}

SynthInputs LoadSynthInputs(const SynthJobOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SynthInputs inputs;
  // Inputs.
  sfm::LoadedModel loaded_model = sfm::ReadModel(options.model_dir);
  if (!loaded_model.choice.empty()) inputs.warnings.push_back(loaded_model.choice);
  inputs.model_folder = loaded_model.folder;
  inputs.reconstruction = std::move(loaded_model.reconstruction);
  const sfm::Reconstruction& reconstruction = inputs.reconstruction;
  const sfm::ObjectLights lights = sfm::ReadObjectLightsFile(options.lights_file);
  const sfm::LightsModelMatch match =
      sfm::CheckLightsAgainstModel(lights, reconstruction, options.lights_file.string());
  for (const std::string& name : match.images_without_lights)
    inputs.warnings.push_back("skipping " + name + ": no light for it in " +
                              options.lights_file.string());
  for (const std::string& name : match.lights_without_images)
    inputs.warnings.push_back("ignoring the light of " + name +
                              ": the COLMAP model does not hold it (not registered?)");
  mesh::LoadedMesh loaded_mesh = mesh::LoadMesh(options.mesh_file);
  for (const std::string& problem : loaded_mesh.report.Problems())
    inputs.warnings.push_back(options.mesh_file.string() + ": " + problem);
  mesh::TriangleMesh& mesh = inputs.mesh;
  mesh = std::move(loaded_mesh.mesh);

  // The photos' headers now, their pixels on demand (PhotoCache).
  std::vector<synth::MeshPhoto>& photos = inputs.photos;
  struct PhotoFile {
    fs::path path;
    cv::Size size;
    int bytes_per_pixel = 12;  // decoded as stored: 3 for 8-bit files, at most 12
  };
  std::vector<PhotoFile> files;
  for (const auto& [id, image] : reconstruction.images) {
    const auto it = lights.find(image.name);
    if (it == lights.end()) continue;
    const fs::path file = options.images_dir / image.name;
    if (!fs::exists(file)) {
      inputs.warnings.push_back("skipping " + image.name + ": no file " + file.string());
      continue;
    }
    const ImageReader header(file);
    const sfm::Camera& camera = reconstruction.cameras.at(image.camera_id);
    if (header.width() != static_cast<int>(camera.width) ||
        header.height() != static_cast<int>(camera.height)) {
      throw InputError(file.string(), "is " + std::to_string(header.width()) + "x" +
                                          std::to_string(header.height()) + " but its camera is " +
                                          std::to_string(camera.width) + "x" +
                                          std::to_string(camera.height));
    }
    synth::MeshPhoto photo;
    photo.image_id = id;
    photo.name = image.name;
    photo.lights = it->second;
    photos.push_back(std::move(photo));
    files.push_back({file, cv::Size(header.width(), header.height()), header.eight_bit() ? 3 : 12});
  }
  std::uint64_t largest = 0, total = 0;
  for (const PhotoFile& file : files) {
    largest = std::max(largest, DecodedPhotoBytes(file.size, file.bytes_per_pixel));
    total += DecodedPhotoBytes(file.size, file.bytes_per_pixel);
  }
  inputs.photo_cache = std::make_shared<PhotoCache>(PhotoCacheBudget(options, largest, total));
  for (std::size_t n = 0; n < photos.size(); ++n)
    photos[n].pixels = PhotoPixels(
        inputs.photo_cache,
        inputs.photo_cache->Add(files[n].path, files[n].size, files[n].bytes_per_pixel));
  if (photos.empty()) {
    throw InputError(options.images_dir.string(),
                     "no usable photo: every image of the model lacks a light or a file");
  }
  inputs.seconds_load = SecondsSince(start);
  return inputs;
}

void CheckWorldUnit(double mm_per_world_unit) {
  if (!(mm_per_world_unit >= 0.0 && std::isfinite(mm_per_world_unit)))
    throw OptionError("the world unit's length must be 0 (not stated) or positive and finite");
}

nlohmann::json WorldUnitJson(double mm_per_world_unit) {
  return mm_per_world_unit > 0.0 ? nlohmann::json(mm_per_world_unit) : nlohmann::json(nullptr);
}

nlohmann::json AtlasSettingsJson(const atlas::AtlasOptions& atlas) {
  return {{"atlas_mode", atlas.mode == atlas::AtlasMode::kCharts ? "charts" : "per_triangle"},
          {"atlas_size", atlas.atlas_size},
          {"gutter", atlas.gutter},
          {"chart_flattening", atlas::ChartFlatteningName(atlas.flattening)},
          {"chart_size", atlas.max_chart_size},
          {"chart_angle_deg", atlas.max_chart_normal_angle_deg},
          {"chart_stretch", atlas.max_chart_stretch}};
}

double LargestPatchSide(const mesh::TriangleMesh& mesh, double sample_texel_size, int strip) {
  double widest = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      widest = std::max(widest, (mesh.Corner(f, (k + 1) % 3) - mesh.Corner(f, k)).norm());
  return widest / sample_texel_size + 2 * strip + 2;
}

void PrepareSynthMesh(SynthInputs& inputs, const SynthJobOptions& options, int sample_side,
                      double sample_texel_size, int strip, const ProgressCallback& progress) {
  const sfm::Reconstruction& reconstruction = inputs.reconstruction;
  const std::vector<synth::MeshPhoto>& photos = inputs.photos;
  mesh::TriangleMesh& mesh = inputs.mesh;
  RefuseSampleLargerThanMesh(mesh, sample_texel_size, options.mesh_file);
  // Visibility (and subdivision while the largest triangle does not fit the sample).
  auto t = std::chrono::steady_clock::now();
  while (LargestPatchSide(mesh, sample_texel_size, strip) > sample_side &&
         inputs.subdivisions < static_cast<std::size_t>(options.max_subdivisions)) {
    mesh = mesh::SubdivideMidpoint(mesh);
    ++inputs.subdivisions;
  }
  if (inputs.subdivisions) {
    inputs.warnings.push_back("subdivided the mesh " + std::to_string(inputs.subdivisions) +
                              " time(s) so that every triangle's patch fits the sample");
  }
  inputs.visibility = sfm::ComputeVisibility(mesh, reconstruction, options.visibility, progress);
  // Photos used here only (visibility saw every image of the model).
  std::size_t seen_by_usable = 0;
  {
    std::map<sfm::ImageId, bool> usable;
    for (const synth::MeshPhoto& p : photos) usable[p.image_id] = true;
    for (const auto& tv : inputs.visibility.triangles) {
      bool seen = false;
      for (const auto& v : tv.views)
        seen = seen || (usable.count(v.image_id) && v.visible_fraction > 0);
      seen_by_usable += seen;
    }
  }
  if (seen_by_usable * 2 < mesh.faces.size()) {
    throw InputError(options.mesh_file.string(),
                     std::to_string(mesh.faces.size() - seen_by_usable) + " of " +
                         std::to_string(mesh.faces.size()) +
                         " triangles project outside every usable photo or face away from it: is "
                         "the mesh in the "
                         "frame of the COLMAP model " +
                         options.model_dir.string() + "?");
  }
  inputs.seconds_visibility = SecondsSince(t);
}

void SynthJobOptions::CheckInputsAndLayout() const {
  for (const auto& [path, what] :
       {std::pair{&model_dir, "COLMAP model folder"}, std::pair{&images_dir, "images folder"},
        std::pair{&lights_file, "lights file"}, std::pair{&mesh_file, "mesh"},
        std::pair{&out_dir, "output folder"}})
    if (path->empty()) throw OptionError(std::string("synth needs a ") + what);
  atlas.Check();
  visibility.Check();
  if (max_subdivisions < 0 || max_subdivisions > 6)
    throw OptionError("max subdivisions must be in [0, 6]");
  for (const int regions : compare_regions)
    if (regions < 2 || regions > 4096)
      throw OptionError("--compare-regions takes 2 to 4096 regions, not " +
                        std::to_string(regions));
  if (!compare_regions.empty() && ranks && ranks->Size() > 1)
    throw OptionError(
        "--compare-regions is for one process: mpirun's manifest measures its own regions");
  if (!sample_horizon_file.empty() && LowerCaseExtension(sample_horizon_file) != ".exr")
    throw OptionError("--sample-horizon is the .exr that texlume fit --horizon writes");
  if (!std::isfinite(atlas_relief_gain) ||
      (atlas_relief_gain > 0.0 && (atlas_relief_gain < 0.25 || atlas_relief_gain > 4.0)))
    throw OptionError("--atlas-relief-gain is auto or in [0.25, 4]");
  if (sample_horizon_file.empty() && (shadowed_synthesis || atlas_relief_gain > 0.0))
    throw OptionError("--shadowed-synthesis and --atlas-relief-gain need --sample-horizon");
  CheckWorldUnit(mm_per_world_unit);
}

nlohmann::json SynthJobOptions::InputsJson() const {
  return {{"model", model_dir.string()},
          {"images", images_dir.string()},
          {"lights", lights_file.string()},
          {"mesh", mesh_file.string()}};
}

const char* FillUnseenName(FillUnseen fill) {
  return fill == FillUnseen::kGraphcut ? "graphcut" : "overlap";
}

synth::MeshSynthesisOptions SynthesisOptionsOf(const SynthJobOptions& job) {
  synth::MeshSynthesisOptions options = job.synthesis;
  // The bake's reads of a patch: its gutter ring (atlas pixels, up to max_chart_stretch
  // texels each) and W_e / 2 texels into a neighbour (atlas/atlas.h).
  options.detail_reach_texels =
      std::max((job.atlas.gutter + 0.5) * job.atlas.max_chart_stretch, 0.5 * job.atlas.blend_strip);
  return options;
}

quilt::UnseenFillOptions UnseenFillOptionsOf(const SynthJobOptions& job, std::uint64_t seed) {
  quilt::UnseenFillOptions fill;
  fill.quilt = job.fill_quilt;
  fill.quilt.seed = seed;
  fill.atlas = job.atlas;
  return fill;
}

void RequireFillMemory(const SynthJobOptions& job, const mesh::TriangleMesh& mesh,
                       double texel_size, int features) {
  RequireMemory(quilt::QuiltingBytes(mesh, texel_size, features),
                "the dense surface of --fill-unseen graphcut",
                job.mesh_file.string() + " at a texel size of " + std::to_string(texel_size));
}

nlohmann::json FillUnseenSettingsJson(const SynthJobOptions& job) {
  nlohmann::json settings = {{"fill_unseen", FillUnseenName(job.fill_unseen)}};
  if (job.fill_unseen == FillUnseen::kGraphcut)
    settings.update({{"fill_work_patch", job.fill_quilt.work_patch_levels},
                     {"fill_seam_threshold", job.fill_quilt.seam_threshold}});
  return settings;
}

nlohmann::json UnseenFillJson(const quilt::UnseenFillSummary& fill) {
  return {{"engine", "graphcut"},
          {"faces", fill.faces},
          {"samples", fill.samples},
          {"given_samples", fill.given_samples},
          {"patches", fill.stats.patches},
          {"forced", fill.stats.forced},
          {"seam_cost_per_cut_link_over_unrelated", quilt::SeamShare(fill.stats)}};
}

void SynthJobOptions::Check() const {
  CheckInputsAndLayout();
  if (sample_file.empty()) throw OptionError("synth needs a sample");
  synthesis.Check();
  if (fill_unseen == FillUnseen::kGraphcut) fill_quilt.Check();
}

std::optional<synth::FaceRegions> RegionsOfJob(const SynthJobOptions& options,
                                               const SynthInputs& inputs,
                                               const synth::TriangleEngineOptions& engine) {
  if (!options.ranks || options.ranks->Size() <= 1) return std::nullopt;
  synth::FaceRegions regions;
  regions.ranks = options.ranks;
  regions.partition =
      synth::RegionsForRanks(mesh::FaceNeighbours(inputs.mesh), options.ranks->Size(), engine.seed);
  return regions;
}

namespace {

nlohmann::json EdgeMismatchJson(const synth::EdgeMismatch& mismatch) {
  const auto tally = [](const synth::EdgeTally& t) {
    return nlohmann::json{
        {"mean", t.Mean()}, {"standard_error", t.StandardError()}, {"edges", t.Edges()}};
  };
  return {{"region_borders", tally(mismatch.region_borders)},
          {"next_to_borders", tally(mismatch.next_to_borders)},
          {"next_to_band", tally(mismatch.next_to_band)},
          {"elsewhere", tally(mismatch.elsewhere)}};
}

}  // namespace

nlohmann::json RegionComparisonJson(const synth::MeshSynthesis& synthesis,
                                    const std::vector<std::array<int, 3>>& neighbours,
                                    int num_regions, std::uint32_t seed) {
  const mesh::FacePartition partition = synth::RegionsForRanks(neighbours, num_regions, seed);
  return {{"regions", num_regions},
          {"region_cut_edges", partition.cut_edges},
          {"edge_mismatch",
           EdgeMismatchJson(synth::MeasureEdgeMismatch(synthesis, partition.region_of_face))}};
}

nlohmann::json RanksJson(const synth::TriangleSynthesis& synthesis,
                         const std::optional<synth::EdgeMismatch>& mismatch) {
  if (synthesis.rank_records.empty()) return nullptr;
  nlohmann::json ranks = nlohmann::json::array();
  for (const synth::RankRecord& r : synthesis.rank_records)
    ranks.push_back({{"rank", r.rank},
                     {"faces", r.faces},
                     {"faces_placed", r.faces_placed},
                     {"seconds_prepare", r.seconds_prepare},
                     {"seconds_region", r.seconds_region},
                     {"seconds_finish", r.seconds_finish},
                     {"bytes_sent", r.bytes_sent},
                     {"patch_memory_bytes", r.patch_memory_bytes},
                     {"peak_resident_bytes", r.peak_resident_bytes}});
  nlohmann::json record = {{"ranks", synthesis.rank_records.size()},
                           {"region_border_faces", synthesis.region_border_faces},
                           {"region_band_faces", synthesis.region_band_faces},
                           {"region_cut_edges", synthesis.region_cut_edges},
                           {"seconds_gather", synthesis.seconds_gather},
                           {"seconds_region_borders", synthesis.seconds_region_borders},
                           {"per_rank", ranks}};
  if (mismatch) record["edge_mismatch"] = EdgeMismatchJson(*mismatch);
  return record;
}

nlohmann::json SynthCounts::ToJson() const {
  return {{"photos_used", photos_used},
          {"faces", faces},
          {"subdivisions", subdivisions},
          {"from_photos", from_photos},
          {"from_neighbours_only", from_neighbours},
          {"random", random},
          {"atlases", atlases},
          {"charts", charts},
          {"chart_flattening", chart_flattening},
          {"occupancy", occupancy},
          {"photo_cache", photo_cache ? PhotoCacheJson(*photo_cache) : nlohmann::json(nullptr)}};
}

nlohmann::json PhotoCacheJson(const PhotoCache& cache) {
  const PhotoCache::Stats stats = cache.stats();
  return {{"budget_bytes", cache.budget_bytes()},
          {"all_photos_bytes", cache.TotalBytes()},
          {"holds_all", cache.HoldsAll()},
          {"decodes", stats.decodes},
          {"hits", stats.hits},
          {"peak_bytes", stats.peak_bytes},
          {"timings_s", {{"decoding", stats.seconds_decoding}}}};
}

void SynthCounts::CountInputs(const SynthInputs& inputs) {
  warnings = inputs.warnings;
  photos_used = inputs.photos.size();
  subdivisions = inputs.subdivisions;
  faces = inputs.mesh.faces.size();
  photo_cache = inputs.photo_cache;
}

nlohmann::json EngineSummaryJson(const synth::TriangleSynthesis& synthesis) {
  return {{"photo_gains", synthesis.photo_gains},
          {"light_response", model::LightResponseJson(synthesis.light_response)},
          {"white_balance", synthesis.white_balance},
          {"photo_blur", synthesis.photo_blur},
          {"tangent_frame", synth::TangentFrameName(synthesis.tangent_frame)},
          {"sample_coherence", synthesis.sample_coherence >= 0.0
                                   ? nlohmann::json(synthesis.sample_coherence)
                                   : nlohmann::json(nullptr)}};
}

void RefuseForeignModelFolder(const fs::path& out) {
  RequireReplaceableFolder(out, "manifest.json", "a texlume model folder");
}

model::TexturedModel TexturedModelOf(const SynthInputs& inputs, std::vector<ptm::Ptm> atlases,
                                     const std::vector<atlas::FacePlacement>& faces) {
  model::TexturedModel model;
  model.mesh = inputs.mesh;
  if (!inputs.mesh.vertices.empty())
    model.orientation =
        sfm::OrientationFromCameras(inputs.reconstruction, mesh::BoundingBoxCentre(inputs.mesh));
  model.atlases = std::move(atlases);
  for (const atlas::FacePlacement& fp : faces) {
    model.face_atlas.push_back(fp.atlas);
    model.corner_px.push_back({fp.corners_px[0].cast<float>(), fp.corners_px[1].cast<float>(),
                               fp.corners_px[2].cast<float>()});
  }
  return model;
}

void AddPhotoViews(const SynthInputs& inputs, const fs::path& images_dir,
                   const std::vector<double>& photo_gains, report::ReportInputs& report,
                   ReportScene& scene) {
  for (std::size_t i = 0; i < inputs.photos.size(); ++i) {
    const synth::MeshPhoto& p = inputs.photos[i];
    const sfm::Image& image = inputs.reconstruction.images.at(p.image_id);
    report.photos.push_back({p.name, images_dir / p.name, p.lights, p.pixels.Held()});
    render::PictureView view;
    view.name = p.name;
    view.camera = inputs.reconstruction.cameras.at(image.camera_id);
    view.cam_from_world = image.cam_from_world;
    view.lights = p.lights;
    view.reference_image = images_dir / p.name;
    view.reference = p.pixels.Held();
    view.reference_gain = i < photo_gains.size() ? photo_gains[i] : 1.0;
    scene.views.push_back(std::move(view));
  }
  report.views_heading = "Photo views under the photos' lights";
}

namespace {

// The main job's steps, each a method, sharing the inputs, the synthesis and
// the model they build (RunSynthJob).
class SynthJob {
 public:
  SynthJob(const SynthJobOptions& options, const ProgressCallback& progress)
      : options_(options), progress_(progress) {}

  SynthJobSummary Run() {
    const auto start = std::chrono::steady_clock::now();
    RefuseForeignModelFolder(options_.out_dir);
    AnnounceStep(progress_, "reading the inputs");
    Load();
    Synthesize();
    if (synthesis_.rank_share_only) return RankShare();
    LayOut();
    AnnounceStep(progress_, "photo baselines");
    Baselines();
    AnnounceStep(progress_, "writing the model folder");
    const auto t = std::chrono::steady_clock::now();
    std::function<void(const fs::path&)> write_report;
    if (options_.write_report)
      write_report = [this](const fs::path& folder) { WriteModelReport(folder); };
    model::WriteModelFolder(options_.out_dir, model_, Record(), extra_images_, write_report);
    summary_.seconds_export = SecondsSince(t) - summary_.seconds_report;
    summary_.seconds_total = SecondsSince(start);
    summary_.model = std::make_shared<const model::TexturedModel>(std::move(model_));
    summary_.baselines = {flat_albedo_, std::move(baked_)};
    return summary_;
  }

 private:
  void Load() {
    inputs_ = LoadSynthInputs(options_);
    sample_ = options_.sample ? Sample{*options_.sample, {}} : ReadSample(options_.sample_file);
    if (!options_.sample_horizon_file.empty()) sample_shadowing_.emplace(options_, sample_);
    PrepareSynthMesh(inputs_, options_, std::min(sample_.ptm.width, sample_.ptm.height),
                     options_.synthesis.sample_texel_size, options_.synthesis.strip, progress_);
    summary_.CountInputs(inputs_);
    summary_.seconds_load = inputs_.seconds_load;
    summary_.seconds_visibility = inputs_.seconds_visibility;
  }

  // The relief's horizon per atlas (--sample-horizon; pipeline/sample_shadowing.h).
  void ShadowAtlases() {
    if (!sample_shadowing_) return;
    const auto t = std::chrono::steady_clock::now();
    sample_shadowing_->ShadowAtlases(model_, progress_);
    summary_.seconds_atlas += SecondsSince(t);
  }

  // Synthesis (Algorithm 2) with the sample's kind.
  void Synthesize() {
    const auto t = std::chrono::steady_clock::now();
    const SynthInputs& in = inputs_;
    const std::optional<synth::FaceRegions> regions =
        RegionsOfJob(options_, in, options_.synthesis);
    const synth::FaceRegions* regions_or_null = regions ? &*regions : nullptr;
    const synth::MeshSynthesisOptions synthesis_options = SynthesisOptionsOf(options_);
    synthesis_ = sample_.colour.empty()
                     ? synth::SynthesizeMeshPtm(
                           in.mesh, in.reconstruction, in.visibility, in.photos, sample_.ptm,
                           synthesis_options, progress_, regions_or_null,
                           sample_shadowing_ ? sample_shadowing_->ForSynthesis() : nullptr)
                     : synth::SynthesizeMeshColour(
                           in.mesh, in.reconstruction, in.visibility, in.photos, sample_.colour,
                           ColourOptions(options_.synthesis), progress_, regions_or_null);
    if (synthesis_.rank_share_only) return;
    if (regions) edge_mismatch_ = synth::MeasureEdgeMismatch(synthesis_, synthesis_.region_of_face);
    summary_.seconds_synthesis = SecondsSince(t);
    if (!regions && !options_.compare_regions.empty()) {
      const std::vector<std::array<int, 3>> neighbours = mesh::FaceNeighbours(in.mesh);
      region_comparison_ = nlohmann::json::array();
      for (const int n : options_.compare_regions)
        region_comparison_.push_back(
            RegionComparisonJson(synthesis_, neighbours, n, options_.synthesis.seed));
    }
    summary_.from_photos = synthesis_.num_from_photos;
    summary_.from_neighbours = synthesis_.num_from_neighbours;
    summary_.random = synthesis_.num_random;
    if (options_.fill_unseen == FillUnseen::kGraphcut) FillUnseenFaces();
  }

  // A rank other than 0: its faces went to rank 0, which writes the model.
  SynthJobSummary RankShare() {
    summary_.rank_share_only = true;
    return summary_;
  }

  // The faces no photo placed, quilted by the graph-cut engine from the
  // synthesis's sample (quilt/unseen_fill.h).
  void FillUnseenFaces() {
    AnnounceStep(progress_, "quilting the faces no photo sees (graph cut)");
    RequireFillMemory(options_, inputs_.mesh, synthesis_.texel_size,
                      synthesis_.CoefficientPlanes());
    summary_.unseen_fill =
        quilt::FillUnseenFaces(inputs_.mesh, synthesis_,
                               UnseenFillOptionsOf(options_, options_.synthesis.seed), progress_);
  }

  // Blending and atlases: the textured model.
  void LayOut() {
    const auto t = std::chrono::steady_clock::now();
    atlas::Atlases atlases =
        atlas::BuildAtlases(inputs_.mesh, synthesis_, options_.atlas, progress_);
    summary_.seconds_atlas = SecondsSince(t);
    summary_.atlases = atlases.ptms.size();
    summary_.charts = static_cast<std::size_t>(atlases.num_charts);
    summary_.chart_flattening = options_.atlas.mode == atlas::AtlasMode::kCharts
                                    ? atlas::ChartFlatteningName(atlases.flattening)
                                    : "none";
    summary_.occupancy = atlases.occupancy;
    summary_.stretch = atlases.stretch;
    model_ = TexturedModelOf(inputs_, std::move(atlases.ptms), atlases.faces);
    model_.light_response = synthesis_.light_response;
    ShadowAtlases();
  }

  // The baselines `texlume render --baseline` draws.
  void Baselines() {
    const auto t = std::chrono::steady_clock::now();
    const SynthInputs& in = inputs_;
    baked_ = render::BakePhotoTextures(model_, in.reconstruction, in.visibility, in.photos,
                                       synthesis_.photo_gains, synthesis_.white_balance);
    flat_albedo_ =
        render::MeanAlbedoFromPhotos(in.mesh, in.reconstruction, in.visibility, in.photos,
                                     synthesis_.photo_gains, synthesis_.white_balance);
    summary_.seconds_baselines = SecondsSince(t);
  }

  nlohmann::json Settings() const {
    const synth::MeshSynthesisOptions& so = options_.synthesis;
    nlohmann::json settings = {
        {"sample_texel_size", so.sample_texel_size},
        {"output_texel_size", so.sample_texel_size},
        {"world_unit_mm", WorldUnitJson(options_.mm_per_world_unit)},
        {"strip", so.strip},
        {"top_k", so.top_k},
        {"search", synth::PlacementSearchName(so.search)},
        {"search_candidates", so.search_candidates},
        {"photometry_faces", so.photometry_faces},
        {"all_views", so.all_views},
        {"max_views", so.max_views},
        {"tangent_frame", synth::TangentFrameName(so.tangent_frame)},
        {"correction_iterations", so.correction_iterations},
        {"additive_correction", so.additive_correction},
        {"correction_noise", so.correction_noise},
        {"channel_correction", so.channel_correction},
        {"detail_transfer", so.detail_transfer},
        {"detail_reach_texels", SynthesisOptionsOf(options_).detail_reach_texels},
        {"correction_prior_shrink", so.correction_prior_shrink < 0.0
                                        ? nlohmann::json("auto")
                                        : nlohmann::json(so.correction_prior_shrink)},
        {"correction_sigma", so.correction_sigma},
        {"horizon_elevation_deg", ptm::kHorizonElevationDeg},
        {"light_response", so.light_response},
        {"view_term", so.view_term},
        {"white_balance", so.white_balance},
        {"photo_blur", so.photo_blur},
        {"seed", so.seed},
        {"compare_regions", options_.compare_regions},
        {"sample_kind", sample_.colour.empty() ? "PTM" : "colour"}};
    settings.update(FillUnseenSettingsJson(options_));
    settings.update(AtlasSettingsJson(options_.atlas));
    return settings;
  }

  nlohmann::json Summary() const {
    const SynthJobSummary& s = summary_;
    nlohmann::json summary = s.ToJson();
    summary.update({{"texel_stretch",
                     {{"mean", s.stretch.mean}, {"min", s.stretch.min}, {"max", s.stretch.max}}},
                    {"mean_prior_shrink", MeanPriorShrink(synthesis_)}});
    summary.update(EngineSummaryJson(synthesis_));
    if (options_.fill_unseen == FillUnseen::kGraphcut)
      summary["unseen_fill"] = UnseenFillJson(s.unseen_fill);
    return summary;
  }

  // The manifest's record: inputs, settings, summary, warnings, baselines, timings.
  nlohmann::json Record() {
    nlohmann::json record;
    record["command"] = "synth";
    record["inputs"] = options_.InputsJson();
    record["inputs"]["sample"] = options_.sample_file.string();
    if (sample_shadowing_) record["inputs"]["sample_horizon"] = sample_shadowing_->Record();
    record["settings"] = Settings();
    record["summary"] = Summary();
    record["warnings"] = summary_.warnings;
    extra_images_ = model::RecordBaselines(flat_albedo_, baked_, record);
    const SynthJobSummary& s = summary_;
    record["timings_s"] = {
        {"load", s.seconds_load},
        {"visibility", s.seconds_visibility},
        {"synthesis", s.seconds_synthesis},
        {"unseen_fill", s.unseen_fill.seconds},
        {"atlas", s.seconds_atlas},
        {"baselines", s.seconds_baselines},
        {"synthesis_per_triangle", s.seconds_synthesis / std::max<std::size_t>(1, s.faces)}};
    record["resources"] = {{"peak_resident_bytes", PeakResidentBytes()},
                           {"patch_memory_estimate_bytes", synthesis_.patch_memory_bytes}};
    if (const nlohmann::json d = RanksJson(synthesis_, edge_mismatch_); !d.is_null())
      record["distributed"] = d;
    if (!region_comparison_.is_null()) record["region_comparison"] = region_comparison_;
    return record;
  }

  void WriteModelReport(const fs::path& folder) {
    const SynthJobSummary& s = summary_;
    report::ReportInputs report;
    report.title = "texlume synth: " + options_.mesh_file.filename().string();
    report.intro =
        "The relightable model texlume synthesised from the photos and the material sample: "
        "the mesh covered with PTM atlases whose detail comes from the sample, chosen triangle "
        "by triangle to agree with the photos under their lights. Below, the model is drawn "
        "from some of the photos' own views under their lights beside the photo (divided by "
        "its estimated exposure) and the two baselines; texlume render measures it on "
        "held-out views.";
    report.model = &model_;
    ReportScene scene;
    scene.model = &model_;
    scene.flat_albedo = flat_albedo_;
    scene.baked = baked_;
    scene.sample = &sample_.ptm;
    AddPhotoViews(inputs_, options_.images_dir, synthesis_.photo_gains, report, scene);
    std::vector<std::vector<sfm::ObjectLight>> photo_lights;
    for (const report::ReportPhoto& p : report.photos) photo_lights.push_back(p.lights);
    report.light_plots = {LightPlotOfModel("the photos' lights", photo_lights, model_)};
    DrawReportPictures(scene, report, progress_);
    report.occupancy = s.occupancy;
    report.facts = {
        {"triangles", std::to_string(s.faces) + " (" + std::to_string(s.from_photos) +
                          " constrained by photos, " + std::to_string(s.from_neighbours) +
                          " by neighbours only" + FilledText() + ")"},
        {"photos used", std::to_string(s.photos_used)},
        {"sample and atlas texel size",
         WorldLengthText(options_.synthesis.sample_texel_size, options_.mm_per_world_unit)},
        {"atlases", std::to_string(s.atlases) + " of " + std::to_string(options_.atlas.atlas_size) +
                        " texels, " + std::to_string(s.charts) + " charts"}};
    for (const std::string& w : s.warnings) report.facts.emplace_back("warning", w);
    report.inputs = InputFiles(options_, inputs_.model_folder);
    report.view_folder = options_.out_dir.string();
    report.texel_size = options_.synthesis.sample_texel_size;
    report.mm_per_world_unit = options_.mm_per_world_unit;
    report.timings_s = {{"load", s.seconds_load},
                        {"visibility", s.seconds_visibility},
                        {"synthesis", s.seconds_synthesis},
                        {"atlas", s.seconds_atlas},
                        {"baselines", s.seconds_baselines}};
    if (options_.fill_unseen == FillUnseen::kGraphcut)
      report.timings_s.insert(report.timings_s.begin() + 3, {"unseen fill", s.unseen_fill.seconds});
    report.links = {
        {"model.glb", "model.glb"}, {"model.obj", "model.obj"}, {"manifest.json", "manifest.json"}};
    summary_.seconds_report = report::WriteReport(folder, report, progress_).seconds;
  }

  std::string FilledText() const {
    if (options_.fill_unseen != FillUnseen::kGraphcut) return "";
    return "; " + std::to_string(summary_.unseen_fill.faces) +
           " seen by no photo, filled by graph-cut quilting";
  }

  const SynthJobOptions& options_;
  const ProgressCallback& progress_;
  SynthJobSummary summary_;
  SynthInputs inputs_;
  Sample sample_;
  synth::MeshSynthesis synthesis_;
  std::optional<synth::EdgeMismatch> edge_mismatch_;  // a distributed run's
  nlohmann::json region_comparison_;                  // one process's (--compare-regions)
  model::TexturedModel model_;
  std::optional<SampleShadowingStage> sample_shadowing_;  // --sample-horizon
  std::vector<cv::Mat> baked_;
  Eigen::Vector3f flat_albedo_ = Eigen::Vector3f::Constant(0.5f);
  std::vector<std::pair<std::string, cv::Mat>> extra_images_;
};

}  // namespace

SynthJobSummary RunSynthJob(const SynthJobOptions& options, const ProgressCallback& progress) {
  options.Check();
  return SynthJob(options, progress).Run();
}

}  // namespace texlume::pipeline
