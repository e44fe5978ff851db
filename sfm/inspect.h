#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "mesh/mesh.h"
#include "sfm/colmap_io.h"
#include "sfm/visibility.h"

namespace texlume::sfm {

/// Inputs of `texlume inspect`.
struct InspectOptions {
  std::filesystem::path model_dir;                  ///< COLMAP model folder (.bin or .txt)
  std::optional<std::filesystem::path> mesh;        ///< coarse mesh in the model's frame
  std::optional<std::filesystem::path> images_dir;  ///< folder the image names are relative to
  std::optional<std::filesystem::path> lights;      ///< object-lights .json or an .lp file
  mesh::MeshCleanOptions mesh_clean;
  VisibilityOptions visibility;

  /// Throws OptionError when no model folder is given or a nested setting is out of range.
  void Check() const;
};

/// Everything `texlume inspect` found.
struct InspectReport {
  ModelFormat format = ModelFormat::kBinary;
  std::filesystem::path model_folder;  ///< the model folder read (FindModelFolder)
  std::string model_choice;            ///< why, when it is not the folder given
  std::vector<std::filesystem::path> ignored_files;
  std::size_t num_cameras = 0;
  std::size_t num_images = 0;
  std::size_t num_registered_images = 0;  ///< every image of a model file is registered
  std::size_t num_points3d = 0;
  std::size_t num_observations = 0;
  double mean_track_length = 0.0;
  double mean_observations_per_image = 0.0;
  double mean_reprojection_error_px = 0.0;
  std::map<std::string, std::size_t> camera_models;  ///< model name -> cameras

  std::optional<mesh::MeshStats> mesh_stats;
  std::optional<mesh::MeshReport> mesh_report;

  std::optional<std::size_t> triangles_fully_seen;      ///< by at least one photo
  std::optional<std::size_t> triangles_partially_seen;  ///< partly, never fully
  std::optional<std::size_t> triangles_unseen;          ///< by no photo
  double visibility_seconds = 0.0;

  std::optional<std::vector<std::string>> missing_images;  ///< when images_dir is given
  std::optional<std::string> lights_kind;                  ///< "object-lights JSON" or ".lp"
  std::size_t num_lit_images = 0;
  std::vector<std::string> images_without_lights;
  /// Light entries naming images the model does not hold (unregistered photos).
  std::vector<std::string> lights_without_images;
};

/// Reads and checks everything given (model, mesh, lights, image folder) and
/// computes visibility coverage when a mesh is given. Throws InputError for
/// unreadable inputs and for lights that name images not in the model; missing
/// image files are reported, not thrown.
InspectReport RunInspect(const InspectOptions& options, const ProgressCallback& progress = {});

/// The human-readable summary printed by `texlume inspect`.
std::string FormatInspectReport(const InspectReport& report);

/// The same summary as a JSON document.
std::string InspectReportToJson(const InspectReport& report);

}  // namespace texlume::sfm
