#pragma once

#include <filesystem>
#include <istream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "sfm/reconstruction.h"

namespace texlume::sfm {

/// The two encodings of a COLMAP sparse model folder.
enum class ModelFormat { kText, kBinary };

/// "txt" or "bin".
std::string ModelFormatName(ModelFormat format);

/// A model read from a folder, with what was found there.
struct LoadedModel {
  Reconstruction reconstruction;
  ModelFormat format = ModelFormat::kBinary;
  /// The model folder read: the one given, or the one found under a workspace.
  std::filesystem::path folder;
  /// Why that folder was taken when it is not the one given (empty otherwise).
  std::string choice;
  /// Files of newer COLMAP versions (rigs, frames) that were present and skipped.
  std::vector<std::filesystem::path> ignored_files;
};

/// Which format a model folder holds: binary when cameras.bin, images.bin and
/// points3D.bin all exist (COLMAP's own preference), else text when the three .txt
/// files exist. Throws InputError naming the folder and the missing files otherwise.
ModelFormat DetectModelFormat(const std::filesystem::path& model_dir);

/// Whether `dir` holds cameras, images and points3D, all .bin or all .txt.
bool IsModelFolder(const std::filesystem::path& dir);

/// The model folder a user means by `path`, as COLMAP lays out a workspace:
/// `path` itself when it is a model folder; else the model folders among `path`,
/// `path/sparse`, and their subfolders (`sparse/0`, `sparse/1`, ...). With several,
/// the one that registers the most images (the lowest-numbered of equals), and
/// `choice` says which were found. Throws InputError naming `path` and every place
/// looked at when there is none.
struct ModelFolderChoice {
  std::filesystem::path folder;
  std::string choice;  ///< empty when `path` is the model folder
};
ModelFolderChoice FindModelFolder(const std::filesystem::path& path);

/// Reads a COLMAP 3.8 sparse model (FindModelFolder: a model folder, `sparse/` or a
/// workspace root) in the detected format and validates its cross references
/// (ValidateReconstruction). Throws InputError on any problem.
LoadedModel ReadModel(const std::filesystem::path& model_dir);
/// Reads a model folder in the given format.
Reconstruction ReadModel(const std::filesystem::path& model_dir, ModelFormat format);

/// Writes cameras, images and points3D in the given format into `model_dir`
/// (created if needed); each file is written atomically.
void WriteModel(const Reconstruction& reconstruction, const std::filesystem::path& model_dir,
                ModelFormat format);

/// Throws InputError(label, ...) when an image names a missing camera, a feature
/// names a missing 3D point, a track names a missing image or an out-of-range
/// feature, or a camera's parameters do not fit its model.
void ValidateReconstruction(const Reconstruction& reconstruction, const std::string& label);

// Stream-level readers and writers; `label` names the stream in errors.
std::map<CameraId, Camera> ReadCamerasText(std::istream& in, const std::string& label);
std::map<ImageId, Image> ReadImagesText(std::istream& in, const std::string& label);
std::map<Point3DId, Point3D> ReadPoints3DText(std::istream& in, const std::string& label);
std::map<CameraId, Camera> ReadCamerasBinary(std::istream& in, const std::string& label);
std::map<ImageId, Image> ReadImagesBinary(std::istream& in, const std::string& label);
std::map<Point3DId, Point3D> ReadPoints3DBinary(std::istream& in, const std::string& label);

void WriteCamerasText(const Reconstruction& reconstruction, std::ostream& out);
void WriteImagesText(const Reconstruction& reconstruction, std::ostream& out);
void WritePoints3DText(const Reconstruction& reconstruction, std::ostream& out);
void WriteCamerasBinary(const Reconstruction& reconstruction, std::ostream& out);
void WriteImagesBinary(const Reconstruction& reconstruction, std::ostream& out);
void WritePoints3DBinary(const Reconstruction& reconstruction, std::ostream& out);

}  // namespace texlume::sfm
