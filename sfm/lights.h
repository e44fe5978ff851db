#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <istream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "sfm/reconstruction.h"

namespace texlume::sfm {

/// One line of an RTI light-position file (.lp).
struct LpEntry {
  std::string filename;  ///< as written in the file (may carry a path)
  /// Unit direction from the surface towards the light in the image/texture frame:
  /// x right, y up (image rows go down), z out of the surface towards the camera.
  Eigen::Vector3d direction_in_image = Eigen::Vector3d::UnitZ();
};

/// Reads an .lp file: first line the count N, then N lines `filename lx ly lz`
/// (the file name may contain spaces: the last three fields are the direction).
/// Directions are normalised. Throws InputError with the line for a bad count,
/// missing lines, unparsable numbers or a zero direction.
std::vector<LpEntry> ReadLp(std::istream& in, const std::string& label);
std::vector<LpEntry> ReadLpFile(const std::filesystem::path& path);
/// Writes an .lp file (17 significant digits).
void WriteLp(const std::vector<LpEntry>& entries, std::ostream& out);
void WriteLpFile(const std::vector<LpEntry>& entries, const std::filesystem::path& path);

/// The file name part of a path written with '/' or '\' separators.
std::string BaseName(const std::string& path);

/// The entry whose file name (base name, exact case) matches `image_name`'s base
/// name, or nullptr. Matching is by name, never by order (DESIGN.md).
const LpEntry* FindLpEntry(const std::vector<LpEntry>& entries, const std::string& image_name);

/// A light of an object photo, in the world frame of the COLMAP model.
struct ObjectLight {
  enum class Kind { kDirectional, kPoint };
  Kind kind = Kind::kDirectional;
  /// kDirectional: unit vector from the surface towards the light (world frame).
  Eigen::Vector3d direction_in_world = Eigen::Vector3d::UnitZ();
  /// kPoint: light position in world units.
  Eigen::Vector3d position_in_world = Eigen::Vector3d::Zero();
  /// Relative radiant intensity (> 0); 1 when the file does not say.
  double intensity = 1.0;

  /// Unit direction from `point_in_world` towards this light.
  Eigen::Vector3d DirectionFrom(const Eigen::Vector3d& point_in_world) const;
};

/// Lights per image name (the name as in the COLMAP model), one or more each.
using ObjectLights = std::map<std::string, std::vector<ObjectLight>>;

/// Reads the object-lights JSON documented in docs/lights.md. Throws InputError
/// (with the line for JSON syntax errors) on any malformed entry.
ObjectLights ReadObjectLights(std::istream& in, const std::string& label);
ObjectLights ReadObjectLightsFile(const std::filesystem::path& path);
void WriteObjectLights(const ObjectLights& lights, std::ostream& out);
void WriteObjectLightsFile(const ObjectLights& lights, const std::filesystem::path& path);

/// How the light entries and the model's images pair up, by name.
struct LightsModelMatch {
  /// Model images with no light: jobs skip them.
  std::vector<std::string> images_without_lights;
  /// Light entries for images the model does not hold (photos SfM did not
  /// register, as COLMAP often leaves a few): jobs ignore them with a warning.
  std::vector<std::string> lights_without_images;
};

/// Pairs lights and images. Throws InputError(label, ...) when no light entry
/// names an image of the model (the file is for other photos), giving a name.
LightsModelMatch CheckLightsAgainstModel(const ObjectLights& lights,
                                         const Reconstruction& reconstruction,
                                         const std::string& label);

}  // namespace texlume::sfm
