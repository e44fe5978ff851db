#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "atlas/atlas.h"
#include "core/progress.h"
#include "quilt/surface_quilting.h"
#include "sfm/visibility.h"
#include "synth/triangle_engine.h"

// `texlume synth --engine graphcut` (issue 32, docs/quilting.md): graph-cut
// quilting of a sample over a mesh (paper 004 §III), without photos or
// following them through paper 003's image term, baked into PTM atlases (or a
// BTF's files) and written as a model folder.

namespace texlume::pipeline {

struct QuiltJobOptions {
  std::filesystem::path mesh_file;
  /// A PTM (.ptm, .exr) or colour image (ReadSample), or a BTF capture or
  /// factorisation folder (btf::ReadOrFactoriseBtf).
  std::filesystem::path sample_file;
  int btf_components = 40;        ///< kept when factorising a BTF capture (paper 004: 40)
  std::filesystem::path out_dir;  ///< the model folder written
  /// Photos to follow (all three, or none): the COLMAP model, the photos and
  /// their object lights, as for the main job; the mesh is then in the model's
  /// frame. Each work patch is placed among the placements whose relit sample
  /// agrees best with the photos (quilt/image_term.h).
  std::filesystem::path model_dir, images_dir, lights_file;
  sfm::VisibilityOptions visibility;
  /// With photos: the per-triangle engine's settings that calibrate them
  /// against the sample and score placements (top_k, all_views, max_views,
  /// light response, white balance, photo blur) and, without a field file,
  /// the frames that give the field (tangent_frame: kAuto follows the photos
  /// for an anisotropic sample). Its texel size is the job's.
  synth::TriangleEngineOptions photo_engine;
  /// Key vectors orienting the sample (quilt/vector_field.h); empty: the world
  /// direction below laid onto every face (synth::TangentFrame::kSmoothField).
  std::filesystem::path field_file;
  Eigen::Vector3d field_direction_in_world = Eigen::Vector3d::UnitZ();
  /// World units per sample texel, > 0; a BTF sample's own when 0.
  double sample_texel_size = 0.0;
  quilt::QuiltOptions quilt;
  /// Also write report.html (and report/) into the model folder: the sample,
  /// the model from four views around it beside flat shading, a light sweep,
  /// the atlases, the quilting's figures and timings.
  bool write_report = true;
  /// How long one world unit is, in millimetres (`--world-unit`); 0 = not stated.
  double mm_per_world_unit = 0.0;
  /// The charts are the dense surface's geometry image: conformal by default.
  atlas::AtlasOptions atlas = ConformalAtlas();
  void Check() const;
  nlohmann::json ToJson() const;
  /// Whether `sample_file` is a BTF folder (a directory).
  bool BtfSample() const;
  /// Whether photos are given (model_dir, images_dir and lights_file).
  bool Photos() const { return !model_dir.empty(); }
  /// The photo settings as the manifest records them (null without photos).
  nlohmann::json PhotosJson() const;

 private:
  void CheckPhotos() const;

 public:
  static atlas::AtlasOptions ConformalAtlas() {
    atlas::AtlasOptions o;
    o.flattening = atlas::ChartFlattening::kConformal;
    return o;
  }
};

struct QuiltJobSummary {
  std::string sample_kind;  ///< "PTM", "colour" or "BTF"
  std::size_t faces = 0, samples = 0, links = 0, chart_seam_links = 0;
  std::size_t photos_used = 0;  ///< with photos
  /// With photos: the photo gains and the frames the photos gave (the
  /// manifest's "photos", EngineSummaryJson).
  nlohmann::json photo_calibration;
  quilt::QuiltStats stats;
  std::size_t atlases = 0, charts = 0;
  double occupancy = 0.0;
  std::vector<std::string> warnings;
  double seconds_sample = 0, seconds_photos = 0, seconds_layout = 0, seconds_photometry = 0,
         seconds_quilting = 0, seconds_atlas = 0, seconds_preview = 0, seconds_report = 0,
         seconds_total = 0;
};

/// Reads the mesh and the sample, lays the faces out in charts, quilts the
/// dense surface and writes the model folder (atomically): PTM atlases for a
/// PTM or colour sample; for a BTF, the BTF files of a BTF model folder
/// (model::BtfModelFiles) with a PTM preview as its atlases. With a texel size
/// given, a dense surface the memory limit cannot hold is refused before the
/// sample is read; with a BTF's own, right after. Throws InputError
/// naming a bad file, OptionError for bad settings (a texel size the memory
/// limit cannot hold is refused before anything is allocated, with the estimate).
QuiltJobSummary RunQuiltJob(const QuiltJobOptions& options, const ProgressCallback& progress = {});

}  // namespace texlume::pipeline
