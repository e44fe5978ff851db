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
  /// Files of newer COLMAP versions (rigs, frames) that were present and skipped.
  std::vector<std::filesystem::path> ignored_files;
};

/// Which format a model folder holds: binary when cameras.bin, images.bin and
/// points3D.bin all exist (COLMAP's own preference), else text when the three .txt
/// files exist. Throws InputError naming the folder and the missing files otherwise.
ModelFormat DetectModelFormat(const std::filesystem::path& model_dir);

/// Reads a COLMAP 3.8 sparse model folder in the detected format and validates
/// its cross references (ValidateReconstruction). Throws InputError on any problem.
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
