// The fuzz targets' seed corpora: small valid files of each format, made by
// texlume's own writers and scene generator (fuzz/fuzz_seeds.h).
#include "fuzz/fuzz_seeds.h"

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "datasets_synthetic/object_scene.h"
#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"
#include "model/model_io.h"
#include "ptm/ptm_io.h"
#include "sfm/colmap_io.h"
#include "sfm/lights.h"

namespace texlume::fuzz {
namespace {

namespace fs = std::filesystem;

void Copy(const fs::path& from, const fs::path& out, const std::string& target,
          const std::string& name) {
  fs::create_directories(out / target);
  fs::copy_file(from, out / target / name, fs::copy_options::overwrite_existing);
}

void Text(const fs::path& out, const std::string& target, const std::string& name,
          const std::string& text) {
  fs::create_directories(out / target);
  std::ofstream(out / target / name, std::ios::binary) << text;
}

void ColmapAndLightSeeds(const fs::path& out, const fs::path& scratch) {
  datasets::ObjectSceneOptions options;
  options.num_images = 3;
  const datasets::ObjectScene scene = datasets::MakeObjectScene(options);
  sfm::WriteModel(scene.reconstruction, scratch / "bin", sfm::ModelFormat::kBinary);
  sfm::WriteModel(scene.reconstruction, scratch / "txt", sfm::ModelFormat::kText);
  for (const char* kind : {"cameras", "images", "points3D"}) {
    std::string target = kind;
    if (target == "points3D") target = "points3d";
    Copy(scratch / "bin" / (std::string(kind) + ".bin"), out, target + "_bin", "scene.bin");
    Copy(scratch / "txt" / (std::string(kind) + ".txt"), out, target + "_txt", "scene.txt");
  }
  sfm::WriteObjectLightsFile(scene.lights, scratch / "lights.json");
  Copy(scratch / "lights.json", out, "object_lights", "scene.json");
  std::vector<sfm::LpEntry> lp(3);
  lp[0] = {"a.png", Eigen::Vector3d(0.5, 0.1, 0.86).normalized()};
  lp[1] = {"b.png", Eigen::Vector3d(-0.3, 0.4, 0.87).normalized()};
  lp[2] = {"c.png", Eigen::Vector3d(0.0, -0.6, 0.8).normalized()};
  sfm::WriteLpFile(lp, scratch / "lights.lp");
  Copy(scratch / "lights.lp", out, "lp", "three.lp");
}

void PtmSeeds(const fs::path& out, const fs::path& scratch) {
  for (const ptm::PtmFormat format : {ptm::PtmFormat::kLrgb, ptm::PtmFormat::kRgb}) {
    ptm::Ptm ptm;
    ptm.Resize(format, 3, 2);
    for (std::size_t i = 0; i < ptm.coefficients.size(); ++i) ptm.coefficients[i] = 0.1f * (i % 7);
    for (float& c : ptm.colour) c = 0.8f;
    const std::string name = format == ptm::PtmFormat::kLrgb ? "lrgb" : "rgb";
    ptm::WritePtmFile(ptm, scratch / (name + ".ptm"));
    ptm::WritePtmExr(ptm, scratch / (name + ".exr"));
    Copy(scratch / (name + ".ptm"), out, "ptm", name + ".ptm");
    Copy(scratch / (name + ".exr"), out, "ptm_exr", name + ".exr");
  }
  // PTM_FORMAT_JPEG_LRGB, 4 x 4: nine grey JPEG streams; plane 1 predicted from plane 0,
  // plane 2 from plane 0 inverted; one side-information record on plane 3.
  std::ostringstream jpeg_ptm;
  jpeg_ptm << "PTM_1.2\nPTM_FORMAT_JPEG_LRGB\n4 4\n2 2 2 1 1 1\n128 128 128 0 0 0\n75\n"
           << "0 0 1 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0\n"
           << "0 1 2 3 4 5 6 7 8\n-1 0 0 -1 -1 -1 -1 -1 -1\n";
  std::string streams;
  std::string sizes, side_sizes;
  for (int p = 0; p < 9; ++p) {
    std::vector<unsigned char> jpeg;
    cv::imencode(".jpg", cv::Mat(4, 4, CV_8UC1, cv::Scalar(40 + 20 * p)), jpeg,
                 {cv::IMWRITE_JPEG_QUALITY, 75});
    streams.append(jpeg.begin(), jpeg.end());
    const std::string side = p == 3 ? std::string("\0\0\0\5\x07", 5) : std::string();
    streams += side;
    sizes += (p ? " " : "") + std::to_string(jpeg.size());
    side_sizes += (p ? " " : "") + std::to_string(side.size());
  }
  jpeg_ptm << sizes << "\n" << side_sizes << "\n" << streams;
  fs::create_directories(out / "ptm");
  std::ofstream(out / "ptm" / "jpeg_lrgb.ptm", std::ios::binary) << jpeg_ptm.str();
}

void MeshSeeds(const fs::path& out, const fs::path& scratch) {
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(1, 1.0);
  for (const char* ext : {"ply", "obj", "off", "stl"}) {
    const fs::path file = scratch / (std::string("sphere.") + ext);
    mesh::SaveMesh(sphere, file);
    Copy(file, out, ext, file.filename().string());
  }
  Text(out, "ply", "ascii.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  Text(out, "obj", "corners.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 -1/1\n");
  Text(out, "off", "colour.off",
       "COFF 3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n0 1 0 1 1 1 1\n3 0 1 2\n");
  Text(out, "stl", "ascii.stl",
       "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
       "endloop\nendfacet\nendsolid t\n");
}

void JsonSeeds(const fs::path& out) {
  Text(out, "btf_json", "capture.json",
       R"({"size": 16, "texel_size": 0.001, "views": [[0, 0, 1], [0.6, 0, 0.8]],)"
       R"( "lights": [[0, 0, 1]], "file_pattern": "view_%02d_light_%02d.png"})");
  nlohmann::json manifest = {
      {"format", "texlume-model"},
      {"atlases", {{{"exr", "ptm_atlas_0.exr"}, {"base_colour", "b.png"}}}},
      {"ptm_evaluation", {{"light_response", model::LightResponseJson(ptm::LightResponse())}}}};
  Text(out, "manifest_json", "manifest.json", manifest.dump(2));
}

}  // namespace

void WriteFuzzSeeds(const std::filesystem::path& out) {
  const fs::path scratch = out / ".scratch";
  fs::create_directories(scratch);
  ColmapAndLightSeeds(out, scratch);
  PtmSeeds(out, scratch);
  MeshSeeds(out, scratch);
  JsonSeeds(out);
  fs::remove_all(scratch);
}

}  // namespace texlume::fuzz
