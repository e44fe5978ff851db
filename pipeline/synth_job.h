#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "atlas/atlas.h"
#include "core/image_io.h"
#include "core/photo_cache.h"
#include "core/progress.h"
#include "model/baselines.h"
#include "model/model_io.h"
#include "pipeline/report_pictures.h"
#include "quilt/surface_quilting.h"
#include "quilt/unseen_fill.h"
#include "render/model_render.h"
#include "sfm/visibility.h"
#include "synth/mesh_synthesis.h"

namespace texlume::pipeline {

/// What the faces no photo sees get (`--fill-unseen`).
enum class FillUnseen {
  kOverlap,   ///< the per-triangle engine's placement by the overlap alone (paper 003)
  kGraphcut,  ///< graph-cut quilting grown out from the faces the photos placed (paper 004 §III)
};
/// "overlap" or "graphcut" (the CLI's and the manifest's names).
const char* FillUnseenName(FillUnseen fill);
struct SynthJobOptions;
/// The job's synthesis options with what follows from its atlas options: how far
/// past a triangle the bake reads its patch (MeshSynthesisOptions::detail_reach_texels).
synth::MeshSynthesisOptions SynthesisOptionsOf(const SynthJobOptions& job);
/// The graph-cut fill's options for a job (its charts; `seed` the synthesis's).
quilt::UnseenFillOptions UnseenFillOptionsOf(const SynthJobOptions& job, std::uint64_t seed);
/// Refuses, with the estimate, a graph-cut fill whose dense surface over the
/// whole mesh (`features` per sample) the memory limit cannot hold.
void RequireFillMemory(const SynthJobOptions& job, const mesh::TriangleMesh& mesh,
                       double texel_size, int features);
/// The manifest's settings of the fill ("fill_unseen", and r_w and T_c when graph cut).
nlohmann::json FillUnseenSettingsJson(const SynthJobOptions& job);
/// The manifest's summary of a graph-cut fill ("unseen_fill").
nlohmann::json UnseenFillJson(const quilt::UnseenFillSummary& fill);

/// Inputs and settings of the main job (`texlume synth`).
struct SynthJobOptions {
  std::filesystem::path model_dir;    ///< COLMAP model (.bin or .txt)
  std::filesystem::path images_dir;   ///< the object photos, by the model's image names
  std::filesystem::path lights_file;  ///< object-lights JSON (docs/lights.md)
  std::filesystem::path mesh_file;    ///< coarse mesh in the model's frame
  std::filesystem::path sample_file;  ///< sample: PTM (.ptm, .exr) or colour photo (ReadSample)
  /// The PTM sample already in memory (borrowed): used instead of reading
  /// `sample_file`, which then only names it in the manifest.
  const ptm::Ptm* sample = nullptr;
  /// Not empty: the PTM sample's horizon map (`texlume fit --horizon`); the model's
  /// atlases then carry the relief's self-shadowing (ptm::ShadowingOfPtm).
  std::filesystem::path sample_horizon_file;
  /// With a horizon map: whether the synthesis (placement, gains, the photo-consistency
  /// pass) also relights the sample with its shadows (`--shadowed-synthesis`), as the
  /// render does; off, only the model casts them (docs/synth.md, "Self-shadowing").
  bool shadowed_synthesis = false;
  /// With a horizon map: the atlases' relief heights times this, [0.25, 4]; <= 0 (auto):
  /// the gain that gives each atlas the sample's share of shadow under low lights
  /// (ptm::MatchLowLightShadowLoss; `--atlas-relief-gain`).
  double atlas_relief_gain = 0.0;
  std::filesystem::path out_dir;          ///< the model folder written
  synth::MeshSynthesisOptions synthesis;  ///< sample_texel_size required
  atlas::AtlasOptions atlas;
  sfm::VisibilityOptions visibility;
  /// The faces no photo sees (quilt/unseen_fill.h), and the graph-cut engine's
  /// settings when it fills them (its seed is the synthesis's).
  FillUnseen fill_unseen = FillUnseen::kOverlap;
  quilt::QuiltOptions fill_quilt;
  /// Split every triangle in four (midpoints) up to this many times while the
  /// largest patch does not fit the sample. [0, 6].
  int max_subdivisions = 4;
  /// Also write report.html (and report/) into the model folder: the sample,
  /// the photos, the model from photo views beside the photos and the
  /// baselines, a light sweep, the atlases, timings (synth/report.h).
  bool write_report = true;
  /// How long one world unit is, in millimetres (`--world-unit`); 0 = not stated. The
  /// report then gives texel and pixel sizes in millimetres as well as world units.
  double mm_per_world_unit = 0.0;
  /// Bytes of decoded photos held at once (`--photo-cache`); 0: half the memory
  /// limit. Never less than the photos one face is constrained by (max_views of
  /// the largest): a smaller value is refused. The photos are decoded on demand
  /// (core/photo_cache.h) and, when they do not all fit, visited photo by photo
  /// (synth/face_order.h).
  std::uint64_t photo_cache_bytes = 0;
  /// The ranks of a distributed run (`mpirun -np N texlume synth`, issue 33;
  /// borrowed; not a setting): the faces are placed region by region, one per
  /// rank (synth/face_regions.h), and rank 0 finishes and writes the model.
  /// Null or one rank: one process.
  synth::RankCommunicator* ranks = nullptr;
  /// One process (`--compare-regions N,...`): also measures the edge mismatch on
  /// the regions `mpirun -np N` would place apart (the same partition), for each N,
  /// so that a distributed run's figures have a one-process baseline on the same
  /// edges (manifest "region_comparison"). Empty: not measured.
  std::vector<int> compare_regions;

  /// Throws OptionError when a path is missing or a setting is out of range.
  void Check() const;
  /// The same, but for the synthesis settings (the BTF job checks its own).
  void CheckInputsAndLayout() const;
  /// The input paths as the manifest's "inputs" names them (the sample's left out).
  nlohmann::json InputsJson() const;
};

/// What the job did (also written to manifest.json).
struct SynthInputs;

/// The manifest's figures of a photo cache: its budget, what every photo would
/// take, decodes, hits, the most bytes held and the time spent decoding.
nlohmann::json PhotoCacheJson(const PhotoCache& cache);

/// What every synth job counts, with any sample (its manifest's summary).
struct SynthCounts {
  std::size_t photos_used = 0, faces = 0, subdivisions = 0;
  std::size_t from_photos = 0, from_neighbours = 0, random = 0;
  std::size_t atlases = 0, charts = 0;
  std::string chart_flattening;  ///< the one used ("auto" resolves to "strips" or "rigid")
  double occupancy = 0.0;
  std::vector<std::string> warnings;  ///< skipped photos, repaired faces, subdivisions
  /// The job's photo cache, whose figures the summary records ("photo_cache").
  std::shared_ptr<const PhotoCache> photo_cache;
  /// A distributed run on a rank other than 0: this rank placed its region's
  /// faces and sent them to rank 0, which writes the model; nothing else was done.
  bool rank_share_only = false;
  /// The counts as the manifest's "summary" names them.
  nlohmann::json ToJson() const;
  /// Takes the counts of the inputs (photos, faces, subdivisions, warnings).
  void CountInputs(const SynthInputs& inputs);
};

struct SynthJobSummary : SynthCounts {
  atlas::AtlasStretch stretch;
  /// The graph-cut fill of the faces no photo sees (FillUnseen::kGraphcut).
  quilt::UnseenFillSummary unseen_fill;
  /// The model and its baselines as written into the model folder.
  std::shared_ptr<const model::TexturedModel> model;
  model::ModelBaselines baselines;
  double seconds_load = 0, seconds_visibility = 0, seconds_synthesis = 0, seconds_atlas = 0,
         seconds_baselines = 0, seconds_report = 0, seconds_export = 0, seconds_total = 0;
};

/// The material sample of the main job: a PTM (.ptm, or an EXR of PTM
/// channels), or an ordinary photo of the material (PNG, JPEG, TIFF, or an EXR
/// of at most 4 channels), which is quilted as a colour sample and baked as
/// its LambertianPtm.
struct Sample {
  ptm::Ptm ptm;    ///< the PTM, or the colour sample's LambertianPtm
  cv::Mat colour;  ///< CV_32FC3 display RGB for a colour sample; empty for a PTM
};
/// Whether a sample file is a colour image (by extension, and channel count for EXR).
bool IsColourImage(const std::filesystem::path& path);
/// Reads a sample file. Throws InputError naming it when it is unreadable.
Sample ReadSample(const std::filesystem::path& path);

/// The main job's inputs, read and checked (shared with the BTF job, btf/).
struct SynthInputs {
  sfm::Reconstruction reconstruction;
  std::filesystem::path model_folder;       ///< the COLMAP model folder read (sfm::FindModelFolder)
  mesh::TriangleMesh mesh;                  ///< subdivided as needed
  std::vector<synth::MeshPhoto> photos;     ///< those with a light and a file
  std::shared_ptr<PhotoCache> photo_cache;  ///< the photos' pixels, decoded on demand
  sfm::VisibilityResult visibility;
  std::vector<std::string> warnings;
  std::size_t subdivisions = 0;
  double seconds_load = 0, seconds_visibility = 0;
};

/// A distributed run's regions of the job's (prepared) mesh, one per rank
/// (synth::RegionsForRanks with the engine's seed); none in one process.
std::optional<synth::FaceRegions> RegionsOfJob(const SynthJobOptions& options,
                                               const SynthInputs& inputs,
                                               const synth::TriangleEngineOptions& engine);
/// The manifest's record of a distributed run (ranks, regions, what each rank
/// did, and for a blended sample the edge mismatch on region borders against
/// elsewhere); null in one process.
nlohmann::json RanksJson(const synth::TriangleSynthesis& synthesis,
                         const std::optional<synth::EdgeMismatch>& mismatch);

/// The edge mismatch of a one-process model on the borders of `num_regions`
/// regions (synth::RegionsForRanks with the engine's seed), with the other two
/// classes, as a distributed run's manifest records its own.
nlohmann::json RegionComparisonJson(const synth::MeshSynthesis& synthesis,
                                    const std::vector<std::array<int, 3>>& neighbours,
                                    int num_regions, std::uint32_t seed);

/// Reads the COLMAP model, object lights, mesh and photos named in `options`
/// (sample and out_dir are not touched). Throws InputError as RunSynthJob describes.
SynthInputs LoadSynthInputs(const SynthJobOptions& options);

/// The side (sample texels) of the largest triangle patch of `mesh`: its
/// longest edge at `sample_texel_size`, with a strip of `strip` texels and a
/// texel of margin on each side. A triangle fits a sample no narrower.
double LargestPatchSide(const mesh::TriangleMesh& mesh, double sample_texel_size, int strip);

/// Splits the mesh while its largest patch (LargestPatchSide) exceeds
/// `sample_side` texels (up to options.max_subdivisions times) and computes
/// visibility. Throws InputError when most triangles are
/// seen by no usable photo (a mesh in another frame).
void PrepareSynthMesh(SynthInputs& inputs, const SynthJobOptions& options, int sample_side,
                      double sample_texel_size, int strip, const ProgressCallback& progress = {});

/// What the engine decided, as the manifests' summaries name it: the photo
/// gains, the frames (kAuto resolved) and the sample's coherence (null when
/// not measured).
nlohmann::json EngineSummaryJson(const synth::TriangleSynthesis& synthesis);

/// The input files a report's provenance names (with their checksums): the COLMAP
/// model's files, the lights, the mesh and the sample file when there is one.
std::vector<std::pair<std::string, std::filesystem::path>> InputFiles(
    const SynthJobOptions& options, const std::filesystem::path& model_folder);

/// Refuses a sample texel size that is not small against the mesh (fewer than 4
/// texels across its bounding box: a texel size in other units than the mesh's),
/// with an OptionError naming the mesh.
void RefuseSampleLargerThanMesh(const mesh::TriangleMesh& mesh, double sample_texel_size,
                                const std::filesystem::path& mesh_path);

/// Refuses an output folder that exists and is not a texlume model folder
/// (InputError naming it): a job never replaces anything else.
void RefuseForeignModelFolder(const std::filesystem::path& out_dir);

/// The textured model of a layout: the inputs' mesh, and per face its atlas and its
/// corners' texture coordinates (FacePlacement), with the atlases; oriented by the
/// inputs' cameras (sfm::OrientationFromCameras about the mesh's bounding box centre).
model::TexturedModel TexturedModelOf(const SynthInputs& inputs, std::vector<ptm::Ptm> atlases,
                                     const std::vector<atlas::FacePlacement>& faces);

/// Runs the whole job: reads and checks the inputs, visibility and best views,
/// per-triangle synthesis (Algorithm 2), blending, atlases, and the model folder
/// (WriteModelFolder, plus the baselines `texlume render` draws: baked_K.png
/// and the flat albedo). Photos in the model without a light or a file are
/// skipped with a warning; it is an InputError when none remains, when most
/// triangles are seen by no photo (a mesh in another frame), or when the
/// patches would not fit in memory. Nothing is written on error.
SynthJobSummary RunSynthJob(const SynthJobOptions& options, const ProgressCallback& progress = {});

/// The photos into a report, and their views into its scene: each photo's
/// camera under its lights, beside the photo divided by its gain.
void AddPhotoViews(const SynthInputs& inputs, const std::filesystem::path& images_dir,
                   const std::vector<double>& photo_gains, report::ReportInputs& report,
                   ReportScene& scene);

/// The atlas settings as the manifests record them (shared by the PTM and BTF jobs).
nlohmann::json AtlasSettingsJson(const atlas::AtlasOptions& atlas);
/// The world unit's length in millimetres as the manifests record it: null when not stated.
nlohmann::json WorldUnitJson(double mm_per_world_unit);
/// Throws OptionError unless the world unit's length is 0 (not stated) or positive and finite.
void CheckWorldUnit(double mm_per_world_unit);

}  // namespace texlume::pipeline
