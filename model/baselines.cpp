#include "model/baselines.h"

#include "core/errors.h"
#include "core/image_io.h"

namespace texlume::model {
namespace fs = std::filesystem;

std::vector<std::pair<std::string, cv::Mat>> RecordBaselines(const Eigen::Vector3f& flat_albedo,
                                                             const std::vector<cv::Mat>& baked,
                                                             nlohmann::json& record) {
  record["baselines"] = {{"flat_albedo", {flat_albedo.x(), flat_albedo.y(), flat_albedo.z()}},
                         {"baked", nlohmann::json::array()}};
  std::vector<std::pair<std::string, cv::Mat>> extra;
  for (std::size_t a = 0; a < baked.size(); ++a) {
    const std::string name = "baked_" + std::to_string(a) + ".png";
    record["baselines"]["baked"].push_back(name);
    extra.emplace_back(name, ToBgr8(baked[a]));
  }
  return extra;
}

ModelBaselines ReadModelBaselines(const fs::path& model_folder, const TexturedModel& model) {
  const fs::path manifest_path = model_folder / "manifest.json";
  const nlohmann::json manifest = ReadModelManifest(model_folder);
  const auto& baselines = manifest.value("baselines", nlohmann::json());
  if (!baselines.is_object()) throw InputError(manifest_path.string(), "lists no baselines");
  ModelBaselines out;
  const auto& a = baselines.value("flat_albedo", nlohmann::json());
  if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() || !a[2].is_number())
    throw InputError(manifest_path.string(), "has no flat_albedo of three numbers");
  out.flat_albedo = Eigen::Vector3f(a[0].get<float>(), a[1].get<float>(), a[2].get<float>());
  const auto& b = baselines.value("baked", nlohmann::json());
  if (!b.is_array() || b.size() != model.atlases.size())
    throw InputError(manifest_path.string(), "has no baked texture per atlas");
  for (std::size_t k = 0; k < b.size(); ++k) {
    if (!b[k].is_string())
      throw InputError(manifest_path.string(), "names a baked texture with no file name");
    const fs::path file = model_folder / ManifestFileName(b[k], model_folder, "baked");
    out.baked.push_back(ReadPhotoRgb(file));
    if (out.baked.back().cols != model.atlases[k].width ||
        out.baked.back().rows != model.atlases[k].height)
      throw InputError(file.string(), "is not the size of its atlas");
  }
  return out;
}

}  // namespace texlume::model
