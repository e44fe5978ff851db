#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "btf/btf.h"
#include "model/model_io.h"

namespace texlume::model {

/// The file of atlas K's per-texel sample coordinates and factors: btf_atlas_K.exr.
std::string BtfAtlasFileName(std::size_t k);

/// Writes one btf_atlas_K.exr: sample_x, sample_y, angle (CV_32FC3
/// `sample_coords`) and gain_r, gain_g, gain_b (CV_32FC3 `colour_gain`).
void WriteBtfAtlas(const std::filesystem::path& file, const cv::Mat& sample_coords,
                   const cv::Mat& colour_gain);

/// The BTF parts of a model folder written by RunBtfSynthJob.
struct BtfModel {
  btf::BtfFactorisation sample;
  std::vector<cv::Mat> sample_coords;  ///< as atlas::BtfAtlases
  std::vector<cv::Mat> colour_gain;    ///< as atlas::BtfAtlases (all 1 when the file has none)
};

/// Reads `btf/` (the factorisation) and `btf_atlas_K.exr` (sample coordinates
/// and photo-consistency factors) of a model folder.
/// Throws InputError naming the file when one is missing, malformed, or its
/// size differs from the model's atlas.
BtfModel ReadBtfModel(const std::filesystem::path& dir, const TexturedModel& model);

}  // namespace texlume::model
