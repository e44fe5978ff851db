#include "model/btf_model.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/image_io.h"
#include "model/packed_textures.h"
#include "ptm/exr_io.h"

namespace texlume::model {
namespace fs = std::filesystem;
namespace {

const std::vector<std::string> kCoordinateChannels = {"sample_x", "sample_y", "angle"};
const std::vector<std::string> kGainChannels = {"gain_r", "gain_g", "gain_b"};

std::string GeometryFileName(std::size_t atlas, std::size_t part) {
  return "btf_geometry_" + std::to_string(atlas) + "_" + std::to_string(part) + ".png";
}

}  // namespace

BtfModelFiles::BtfModelFiles(const btf::BtfFactorisation& sample,
                             std::vector<cv::Mat> sample_coords, std::vector<cv::Mat> colour_gain,
                             const std::vector<std::vector<cv::Mat>>& geometry)
    : sample_(sample),
      sample_coords_(std::move(sample_coords)),
      colour_gain_(std::move(colour_gain)) {
  nlohmann::json atlas_files = nlohmann::json::array();
  for (std::size_t a = 0; a < sample_coords_.size(); ++a)
    atlas_files.push_back(BtfAtlasFileName(a));
  manifest_ = {
      {"format", "texlume-btf-model-1"},
      {"factorisation", "btf/btf_svd.json"},
      {"atlases", atlas_files},
      {"atlas_channels", "sample_x, sample_y, angle, gain_r, gain_g, gain_b (docs/btf.md)"},
      {"ptm_atlases", "a preview: the BTF seen head-on, fitted per texel"}};
  manifest_["geometry_atlases"] = EncodeGeometry(geometry);
}

nlohmann::json BtfModelFiles::EncodeGeometry(const std::vector<std::vector<cv::Mat>>& geometry) {
  nlohmann::json geometry_json = nlohmann::json::array();
  for (std::size_t a = 0; a < geometry.size(); ++a) {
    const std::vector<cv::Mat>& planes = geometry[a];
    const int w = planes[0].cols, h = planes[0].rows;
    std::vector<QuantisedPlane> quantised(planes.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t i = 0; i < planes.size(); ++i) {
      const cv::Mat flat = planes[i].reshape(1, 1);
      quantised[i] = QuantisePlane(std::vector<float>(flat.begin<float>(), flat.end<float>()));
    }
    const std::size_t parts = (planes.size() + 3) / 4;
    geometry_png_.resize(geometry_png_.size() + parts);
    const std::size_t first = geometry_png_.size() - parts;
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t part = 0; part < parts; ++part) {
      std::vector<const QuantisedPlane*> group;
      for (std::size_t i = part * 4; i < std::min(planes.size(), part * 4 + 4); ++i)
        group.push_back(&quantised[i]);
      const std::string name = GeometryFileName(a, part);
      geometry_png_[first + part] = {name, PlanesPng(group, w, h, name)};
    }
    nlohmann::json files = nlohmann::json::array();
    for (std::size_t part = 0; part < parts; ++part) {
      nlohmann::json scale = nlohmann::json::array(), bias = nlohmann::json::array();
      for (std::size_t i = part * 4; i < std::min(planes.size(), part * 4 + 4); ++i)
        scale.push_back(quantised[i].scale), bias.push_back(quantised[i].bias);
      files.push_back({{"file", GeometryFileName(a, part)}, {"scale", scale}, {"bias", bias}});
    }
    geometry_json.push_back(files);
  }
  return geometry_json;
}

void BtfModelFiles::Write(const fs::path& folder) const {
  btf::WriteBtfFactorisation(sample_, btf::SvdErrorTable(sample_), folder / "btf");
  for (std::size_t a = 0; a < sample_coords_.size(); ++a)
    WriteBtfAtlas(folder / BtfAtlasFileName(a), sample_coords_[a], colour_gain_[a]);
  for (const auto& [name, bytes] : geometry_png_) WriteBytesAtomically(folder / name, bytes);
}

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
                     "describes no BTF model (made by texlume synth with a BTF sample)");
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
