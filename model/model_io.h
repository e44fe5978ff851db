#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/image_io.h"
#include "core/json_io.h"
#include "mesh/mesh.h"
#include "ptm/horizon.h"
#include "ptm/ptm.h"
#include "sfm/alignment.h"

namespace texlume::model {

/// A relightable model: the mesh, texture coordinates per face corner in atlas
/// pixels (x right, y down, pixel centres at +0.5), the atlas of each face, and
/// the PTM atlases. Each atlas texel's coefficients are in the tangent frame of
/// the texture coordinates: x = dP/du, y = dP/dv with v up, z = face normal.
/// `light_response`: how the texels answer light beyond the biquadratic, as the
/// photos showed it (ptm::LightResponse; the identity for models written before
/// it). A BTF model's preview carries the BTF's, which render::ShadeBtf applies.
/// The base-colour PNGs and the .ptm/.exr atlases hold the biquadratic alone.
struct TexturedModel {
  mesh::TriangleMesh mesh;
  std::vector<std::array<Eigen::Vector2f, 3>> corner_px;
  std::vector<int> face_atlas;
  std::vector<ptm::Ptm> atlases;
  /// Empty, or one per atlas (its size): the relief's horizon and shadow floor, from a
  /// sample fitted with `texlume fit --horizon` (ptm/horizon.h).
  std::vector<ptm::SelfShadowing> shadowing;
  ptm::LightResponse light_response;
  /// Up and the photos' side in the model's frame (sfm::OrientationFromCameras): how
  /// the GLB stands in glTF's frame. COLMAP's convention when not set.
  sfm::ViewingOrientation orientation;
};

/// The light response as the manifest's and the glTF extras' "ptm_evaluation"
/// record it: knot elevations (degrees), factors and ambient.
nlohmann::json LightResponseJson(const ptm::LightResponse& response);
/// Reads LightResponseJson's record; throws InputError naming `file` when it is
/// malformed or out of range.
ptm::LightResponse LightResponseFromJson(const nlohmann::json& record, const std::string& file);

/// Writes the model into `dir` (created; an existing texlume model folder there
/// is replaced, anything else is an error): model.obj + model.mtl with
/// base_colour_K.png (the PTM at a head-on light), albedo_K.png and normal_K.png
/// (the PTM normals; the MTL's `norm` and `map_Bump`), vertex normals (`vn`); the PTM
/// atlases as ptm_atlas_K.ptm and lossless ptm_atlas_K.exr; model.glb (glb_writer.h:
/// glTF's frame, albedo, normal map, the PTM atlases embedded); manifest.json listing every file
/// with `record` (settings, timings) merged in. Everything is written under a temporary name first
/// and renamed into place, so a failure leaves no half-written folder. `extra_images`: further PNGs
/// to include (name -> 8-bit BGR image); `write_more`, when set, writes further files into the
/// temporary folder it is given (listed in the manifest too, by their paths relative to `dir`).
void WriteModelFolder(const std::filesystem::path& dir, const TexturedModel& model,
                      const nlohmann::json& record,
                      const std::vector<std::pair<std::string, cv::Mat>>& extra_images = {},
                      const std::function<void(const std::filesystem::path&)>& write_more = {});

/// Reads and checks a model folder's manifest.json (format "texlume-model", an
/// "atlases" array). Throws InputError naming the file otherwise.
nlohmann::json ReadModelManifest(const std::filesystem::path& dir);

/// A file name the manifest of the model folder `dir` gives under `key`: throws
/// InputError naming manifest.json unless it is a string naming a file inside
/// `dir` (relative, no ".." component; core/file_util.h ContainedPath).
std::string ManifestFileName(const nlohmann::json& value, const std::filesystem::path& dir,
                             const std::string& key);

/// The frame face f's atlas coefficients are in, as columns in world
/// coordinates: x = dP/du made orthogonal to the normal, y = n x x (dP/dv
/// direction, v up), z = the face normal (x = the first edge without texture
/// coordinates).
Eigen::Matrix3d AtlasFaceFrame(const TexturedModel& model, std::size_t f);

/// One face corner as the exporters write it (every corner on its own: charts meet at
/// seams).
struct ModelCorner {
  std::size_t face = 0;
  int atlas = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();        ///< model frame
  Eigen::Vector3d smooth_normal = Eigen::Vector3d::UnitZ();  ///< mesh::VertexNormals
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();       ///< AtlasFaceFrame of the face
  /// Texture coordinates in [0, 1] of the face's atlas: x right, y down (the atlas's first
  /// row at 0, as glTF has them; v up is 1 - y).
  Eigen::Vector2f uv_down = Eigen::Vector2f::Zero();
};
/// Visits every face corner, the faces in order of their atlas (by face index within
/// one), a face's three corners in turn.
void ForEachCornerByAtlas(const TexturedModel& model,
                          const std::function<void(const ModelCorner&)>& visit);

/// Reads a model folder written by WriteModelFolder (its manifest, OBJ and EXR
/// atlases). Throws InputError naming the file on anything malformed.
TexturedModel ReadModelFolder(const std::filesystem::path& dir);

/// The PTM relit at a head-on light (base colour) and the Lambertian albedo
/// (head-on value over the PTM normal's z, linear domain), as 8-bit BGR images.
cv::Mat BaseColourImage(const ptm::Ptm& ptm);
cv::Mat AlbedoImage(const ptm::Ptm& ptm);
/// The PTM normals (ptm::NormalMap) as a tangent-space normal map in the atlas frame
/// (x = dP/du, y = dP/dv with v up, z = the face normal): 8-bit BGR of (n + 1) / 2,
/// linear, the convention of glTF's normalTexture and of Blender (+Y up the image).
cv::Mat NormalMapImage(const ptm::Ptm& ptm);

}  // namespace texlume::model
