#include "model/btf_model.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "ptm/exr_io.h"

namespace texlume::model {
namespace fs = std::filesystem;
namespace {

const std::vector<std::string> kCoordinateChannels = {"sample_x", "sample_y", "angle"};
const std::vector<std::string> kGainChannels = {"gain_r", "gain_g", "gain_b"};

}  // namespace

std::string BtfAtlasFileName(std::size_t k) { return "btf_atlas_" + std::to_string(k) + ".exr"; }

void WriteBtfAtlas(const fs::path& file, const cv::Mat& sample_coords, const cv::Mat& colour_gain) {
  std::vector<cv::Mat> planes, gain;
  cv::split(sample_coords, planes);
  cv::split(colour_gain, gain);
  planes.insert(planes.end(), gain.begin(), gain.end());
  std::vector<std::string> names = kCoordinateChannels;
  names.insert(names.end(), kGainChannels.begin(), kGainChannels.end());
  ptm::WriteExr(file, planes, names);
}

BtfModel ReadBtfModel(const fs::path& dir, const TexturedModel& model) {
  const nlohmann::json manifest = ReadModelManifest(dir);
  const fs::path manifest_path = dir / "manifest.json";
  if (!manifest.contains("btf") || !manifest["btf"].is_object())
    throw InputError(manifest_path.string(),
                     "describes no BTF model (made by texlume synth --btf)");
  BtfModel out;
  out.sample = btf::ReadBtfFactorisation(dir / "btf");
  for (std::size_t k = 0; k < model.atlases.size(); ++k) {
    const fs::path file = dir / BtfAtlasFileName(k);
    if (!fs::exists(file)) throw InputError(file.string(), "is missing");
    std::vector<std::string> names;
    const std::vector<cv::Mat> planes = ptm::ReadExr(file, &names);
    std::vector<cv::Mat> ordered;  // EXR keeps channels sorted by name
    for (const std::string& want : kCoordinateChannels) {
      const auto it = std::find(names.begin(), names.end(), want);
      if (it == names.end())
        throw InputError(file.string(),
                         "has no channel " + want + " (expected sample_x, sample_y, angle)");
      ordered.push_back(planes[static_cast<std::size_t>(it - names.begin())]);
    }
    if (ordered[0].cols != model.atlases[k].width || ordered[0].rows != model.atlases[k].height)
      throw InputError(file.string(), "is not the size of its atlas");
    cv::Mat coords;
    cv::merge(ordered, coords);
    out.sample_coords.push_back(coords);
    // The photo-consistency factors (absent from models made without them: 1).
    std::vector<cv::Mat> gain;
    for (const std::string& want : kGainChannels) {
      const auto it = std::find(names.begin(), names.end(), want);
      if (it != names.end()) gain.push_back(planes[static_cast<std::size_t>(it - names.begin())]);
    }
    if (!gain.empty() && gain.size() != 3)
      throw InputError(file.string(), "has some but not all of gain_r, gain_g, gain_b");
    cv::Mat factors(coords.size(), CV_32FC3, cv::Scalar::all(1.0));
    if (!gain.empty()) cv::merge(gain, factors);
    out.colour_gain.push_back(factors);
  }
  return out;
}

}  // namespace texlume::model
