#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "model/model_io.h"

namespace texlume::model {

/// The baselines `texlume synth` stored in a model folder (manifest.json's
/// "baselines": the flat albedo and one baked texture per atlas).
struct ModelBaselines {
  Eigen::Vector3f flat_albedo = Eigen::Vector3f::Constant(0.5f);
  std::vector<cv::Mat> baked;  ///< CV_32FC3 display RGB, per atlas
};
/// Records the baselines in a manifest `record` ("baselines": the flat albedo
/// and baked_K.png per atlas) and returns those PNGs (8-bit BGR) for
/// WriteModelFolder's extra images.
std::vector<std::pair<std::string, cv::Mat>> RecordBaselines(const Eigen::Vector3f& flat_albedo,
                                                             const std::vector<cv::Mat>& baked,
                                                             nlohmann::json& record);
/// Throws InputError naming the manifest or texture when missing or malformed.
ModelBaselines ReadModelBaselines(const std::filesystem::path& model_folder,
                                  const TexturedModel& model);

}  // namespace texlume::model
