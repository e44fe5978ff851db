// The parsers the fuzz targets drive (fuzz/fuzz_target.cpp) and the regression
// test replays (tests/fuzz/fuzz_inputs_test.cpp).
#include "fuzz/fuzz_inputs.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "btf/btf.h"
#include "core/errors.h"
#include "mesh/mesh.h"
#include "mesh/mesh_readers.h"
#include "model/model_io.h"
#include "ptm/ptm_io.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"

namespace texlume::fuzz {
namespace {

namespace fs = std::filesystem;

// A folder of this process for parsers that read files by path, removed at exit.
struct Scratch {
  Scratch() : path(fs::temp_directory_path() / ("texlume_fuzz_" + std::to_string(::getpid()))) {
    fs::create_directories(path);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path path;
};
const fs::path& ScratchFolder() {
  static const Scratch scratch;
  return scratch.path;
}

fs::path WriteScratch(const std::string& name, std::string_view bytes) {
  const fs::path path = ScratchFolder() / name;
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

// The soup as LoadMesh goes on with it: refused without faces, then repaired.
void CleanSoup(const mesh::PolygonSoup& soup) {
  if (soup.polygons.empty()) throw InputError("mesh", "the mesh has no faces");
  mesh::CleanMesh(soup.vertices, soup.polygons, {}, "mesh");
}

void ParseModelFolder(std::string_view bytes) {
  const fs::path folder = ScratchFolder() / "model";
  fs::create_directories(folder);
  WriteScratch("model/manifest.json", bytes);
  const nlohmann::json manifest = model::ReadModelManifest(folder);
  for (const auto& entry : manifest["atlases"]) {
    if (entry.is_object() && entry.contains("exr"))
      model::ManifestFileName(entry["exr"], folder, "exr");
  }
  const auto& evaluation = manifest.value("ptm_evaluation", nlohmann::json());
  if (evaluation.is_object() && evaluation.contains("light_response"))
    model::LightResponseFromJson(evaluation["light_response"], "manifest.json");
}

void ParseBtfJson(std::string_view bytes) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(bytes);
  } catch (const nlohmann::json::exception& e) {
    throw InputError("btf.json", std::string("is not valid JSON: ") + e.what());  // as ReadJsonFile
  }
  btf::ParseBtfJson(j, ScratchFolder(), "btf.json");
}

}  // namespace

const std::vector<std::string>& Targets() {
  static const std::vector<std::string> targets = {
      "cameras_bin", "images_bin",    "points3d_bin", "cameras_txt",  "images_txt", "points3d_txt",
      "lp",          "object_lights", "ptm",          "ptm_exr",      "ply",        "obj",
      "off",         "stl",           "btf_json",     "manifest_json"};
  return targets;
}

void ParseInput(std::string_view target, std::string_view bytes) {
  std::istringstream in{std::string(bytes)};
  if (target == "cameras_bin")
    sfm::ReadCamerasBinary(in, "cameras.bin");
  else if (target == "images_bin")
    sfm::ReadImagesBinary(in, "images.bin");
  else if (target == "points3d_bin")
    sfm::ReadPoints3DBinary(in, "points3D.bin");
  else if (target == "cameras_txt")
    sfm::ReadCamerasText(in, "cameras.txt");
  else if (target == "images_txt")
    sfm::ReadImagesText(in, "images.txt");
  else if (target == "points3d_txt")
    sfm::ReadPoints3DText(in, "points3D.txt");
  else if (target == "lp")
    sfm::ReadLp(in, "lights.lp");
  else if (target == "object_lights")
    sfm::ReadObjectLights(in, "lights.json");
  else if (target == "ptm")
    ptm::ReadPtm(in, "sample.ptm");
  else if (target == "ptm_exr")
    ptm::ReadPtmExrBytes(bytes, "sample.exr");
  else if (target == "ply")
    CleanSoup(mesh::ParsePly(bytes, "mesh.ply"));
  else if (target == "obj")
    CleanSoup(mesh::ParseObj(bytes, "mesh.obj"));
  else if (target == "off")
    CleanSoup(mesh::ParseOff(bytes, "mesh.off"));
  else if (target == "stl")
    CleanSoup(mesh::ParseStl(bytes, "mesh.stl"));
  else if (target == "btf_json")
    ParseBtfJson(bytes);
  else if (target == "manifest_json")
    ParseModelFolder(bytes);
  else
    throw std::invalid_argument("unknown fuzz target " + std::string(target));
}

}  // namespace texlume::fuzz
