#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/model_io.h"

namespace texlume::model {

/// The name of the glTF extension under which a material carries its PTM atlas
/// (docs/model_format.md, "The GLB").
inline constexpr const char* kGltfPtmExtension = "TEXLUME_ptm_atlas";

/// What the GLB embeds for one atlas.
struct GlbAtlas {
  std::vector<unsigned char> albedo_png;  ///< baseColorTexture (sRGB)
  std::vector<unsigned char> normal_png;  ///< normalTexture (linear, tangent space)
  /// The PTM atlas's planes as relight's web format holds them (ptm::QuantiseWebPlanes),
  /// PNG-encoded, for TEXLUME_ptm_atlas.
  std::vector<std::vector<unsigned char>> ptm_plane_pngs;
  nlohmann::json ptm_fields;  ///< TEXLUME_ptm_atlas's other fields (scale, bias, frame...)
  /// The relief's horizon when the model casts its shadows (EncodeHorizonTextures):
  /// TEXLUME_ptm_atlas's `horizon`, its PNGs as `textures`. Empty: no horizon.
  std::vector<std::vector<unsigned char>> horizon_pngs;
  nlohmann::json horizon_fields;
  nlohmann::json extras;  ///< the material's extras
};

/// glTF's frame from the model's (COLMAP's) as a 4 x 4 matrix: rows of the rotation
/// (up x front, up, front) of `model.orientation`, so up goes to glTF's +Y and the
/// photos' side to +Z; then the bounding box's centre moved onto the Y axis and its
/// lowest point to Y = 0. No scale: one glTF unit is one unit of the model.
Eigen::Matrix4d GltfFromModel(const TexturedModel& model);

/// Writes a glTF 2.0 binary. The mesh keeps the model's coordinates and its node's
/// matrix is GltfFromModel (the node's extras hold it and its inverse). One
/// primitive and material per atlas: positions, smooth normals, tangents along the
/// atlas frame's x (so the normal map's axes are the PTM's), TEXCOORD_0 (glTF's v
/// down); the albedo as base colour, the PTM normals as normal map, and the PTM atlas's
/// coefficient planes (and the relief's horizon, when it has one) under the
/// TEXLUME_ptm_atlas extension. Throws std::runtime_error when
/// the file would exceed the 4 GiB a GLB can hold.
void WriteGlb(const std::filesystem::path& path, const TexturedModel& model,
              const std::vector<GlbAtlas>& atlases);

}  // namespace texlume::model
