#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
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

/// The BTF files of a model folder (docs/btf.md), encoded before the folder is
/// written: the factorisation (`btf/`), per atlas the sample coordinates and
/// factors (`btf_atlas_K.exr`) and the geometry maps baked per texel
/// (`btf_geometry_K_P.png`: 8 bits with a scale and bias per component, four
/// components per RGBA PNG). Every BTF engine's job writes its folder with it.
class BtfModelFiles {
 public:
  /// `sample_coords`, `colour_gain` (CV_32FC3) and `geometry` (n CV_32FC1
  /// planes) per atlas, as atlas::BtfAtlases holds them.
  BtfModelFiles(const btf::BtfFactorisation& sample, std::vector<cv::Mat> sample_coords,
                std::vector<cv::Mat> colour_gain,
                const std::vector<std::vector<cv::Mat>>& geometry);
  BtfModelFiles(btf::BtfFactorisation&&, std::vector<cv::Mat>, std::vector<cv::Mat>,
                const std::vector<std::vector<cv::Mat>>&) = delete;  // it keeps the sample
  /// The manifest's "btf" section.
  const nlohmann::json& Manifest() const { return manifest_; }
  /// Writes the files into the folder being written (WriteModelFolder's callback).
  void Write(const std::filesystem::path& folder) const;

 private:
  nlohmann::json EncodeGeometry(const std::vector<std::vector<cv::Mat>>& geometry);

  const btf::BtfFactorisation& sample_;
  std::vector<cv::Mat> sample_coords_, colour_gain_;  ///< shared with the caller's (cv::Mat)
  std::vector<std::pair<std::string, std::vector<unsigned char>>> geometry_png_;
  nlohmann::json manifest_;
};

/// The BTF parts of a model folder written by BtfModelFiles.
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
