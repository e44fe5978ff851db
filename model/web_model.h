#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/model_io.h"
#include "model/packed_textures.h"

namespace texlume::model {

/// A model folder prepared for the browser viewer (docs/viewer.md): a scene
/// description, the geometry as float32 vertex streams, and the PTM atlases as
/// 8-bit channels with a scale and bias each, four per RGBA PNG.
struct WebModel {
  nlohmann::json scene;                                     ///< "scene.json"
  std::map<std::string, std::vector<unsigned char>> files;  ///< name -> bytes, scene.json included
};

/// Charts of a model: faces are in one chart when they share a mesh edge whose
/// two corners have the same texture coordinates on both sides (within 1e-3
/// texels) in the same atlas. Returns the chart id of every face (0-based).
std::vector<int> ChartsOfModel(const TexturedModel& model);

/// Per atlas (CV_32SC1, its size), the chart (ChartsOfModel) of each texel a face of
/// that chart covers (its texel centres rasterised with their edges; the report's
/// occupancy counts them); -1 elsewhere (gutters, empty space).
std::vector<cv::Mat> AtlasChartRegions(const TexturedModel& model);

/// Builds the web model of a model folder written by WriteModelFolder (reads
/// its manifest, OBJ, EXR atlases and baked textures). Throws InputError naming
/// the file on anything malformed.
WebModel BuildWebModel(const std::filesystem::path& model_dir);

}  // namespace texlume::model
