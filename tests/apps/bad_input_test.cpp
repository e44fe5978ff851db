// The catalogue of bad inputs (issue 30), run through the texlume program as a
// user runs it: each case must end with the documented exit code (1 for a bad
// file, 2 for a bad setting), a message that names the offending file (or
// option), and no output left behind, not even a partial one. One ctest for all
// the cases, which share one prepared workspace.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <functional>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "datasets_synthetic/object_scene.h"
#include "ptm/ptm.h"
#include "ptm/ptm_io.h"
#include "sfm/colmap_io.h"
#include "tests/test_util.h"

namespace texlume {
namespace {

namespace fs = std::filesystem;
using testing::ReadText;
using testing::RunCommand;
using testing::TempDir;
using testing::WriteText;

// A folder with a small object scene (sparse/, sparse_txt/, mesh.ply,
// lights.json), a PTM, two photos and a BTF capture's btf.json, for the cases
// to damage: made once per run, and copied into each case's folder.
class Workspace {
 public:
  explicit Workspace(const fs::path& dir) : dir_(dir) {
    fs::copy(Prepared(), dir_, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  }
  std::string operator()(const std::string& name) const { return (dir_ / name).string(); }
  const fs::path& dir() const { return dir_; }

 private:
  static void Make(const fs::path& dir) {
    datasets::ObjectSceneOptions options;
    options.num_images = 4;
    datasets::WriteObjectScene(datasets::MakeObjectScene(options), dir);
    ptm::Ptm ptm;
    ptm.Resize(ptm::PtmFormat::kLrgb, 4, 4);
    for (float& c : ptm.colour) c = 1.0f;
    for (std::size_t t = 0; t < ptm.NumTexels(); ++t) ptm.Coefficients(t)[5] = 0.5f;
    ptm::WritePtmFile(ptm, dir / "sample.ptm");
    fs::create_directories(dir / "photos");
    for (const char* name : {"a.png", "b.png"})
      cv::imwrite((dir / "photos" / name).string(), cv::Mat(32, 32, CV_8UC3, cv::Scalar(9, 9, 9)));
  }
  static const fs::path& Prepared() {
    struct Folder {  // removed at exit
      Folder()
          : path(fs::temp_directory_path() /
                 ("texlume_bad_input_workspace_" + std::to_string(::getpid()))) {
        fs::remove_all(path);
        fs::create_directories(path);
        Make(path);
      }
      ~Folder() {
        std::error_code ec;
        fs::remove_all(path, ec);
      }
      fs::path path;
    };
    static const Folder prepared;
    return prepared.path;
  }

  fs::path dir_;
};

struct BadInput {
  std::string name;
  // Damages the workspace and returns the texlume arguments to run.
  std::function<std::string(const Workspace&)> prepare;
  int exit_code;
  std::string named;   // must appear in the message (the file or the option)
  std::string output;  // relative to the workspace: must not exist afterwards
};

// gtest names a case by its name, not its bytes.
void PrintTo(const BadInput& c, std::ostream* os) { *os << c.name; }

std::string InspectMesh(const Workspace& w, const std::string& mesh_name, const std::string& text) {
  WriteText(w.dir() / mesh_name, text);
  return "inspect --model " + w("sparse") + " --mesh " + w(mesh_name) + " --json " + w("out.json");
}

const char kPlyHead[] = "ply\nformat ascii 1.0\n";

// Writes a binary COLMAP model into `sparse` after `change` edits it.
std::string WithModel(const Workspace& w, const std::function<void(sfm::Reconstruction&)>& change) {
  sfm::Reconstruction r = sfm::ReadModel(w.dir() / "sparse").reconstruction;
  change(r);
  sfm::WriteModel(r, w.dir() / "sparse", sfm::ModelFormat::kBinary);
  return "inspect --model " + w("sparse") + " --mesh " + w("mesh.ply") + " --json " + w("out.json");
}

// A model folder whose manifest and OBJ texlume reads before it renders.
std::string RenderModel(const Workspace& w, const std::string& manifest, const std::string& obj) {
  fs::create_directories(w.dir() / "model");
  WriteText(w.dir() / "model/manifest.json", manifest);
  WriteText(w.dir() / "model/model.obj", obj);
  ptm::WritePtmExr(ptm::ReadPtmAnyFormat(w.dir() / "sample.ptm"), w.dir() / "model/a.exr");
  return "render --model " + w("model") + " --cameras " + w("sparse") + " --lights " +
         w("lights.json") + " --out " + w("render");
}

std::string Manifest(const std::string& exr) {
  return R"({"format": "texlume-model", "atlases": [{"exr": ")" + exr + R"("}]})";
}

const char kGoodObj[] =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl atlas_0\nf 1/1 2/2 3/3\n";

std::string Btf(const Workspace& w, const std::string& pattern) {
  fs::create_directories(w.dir() / "capture");
  WriteText(w.dir() / "capture/btf.json",
            R"({"size": 32, "texel_size": 0.001, "views": [[0, 0, 1]], "lights": [[0, 0, 1]],
                "file_pattern": ")" +
                pattern + R"("})");
  return "btf --capture " + w("capture") + " --out " + w("btf_out");
}

std::string PtmText(const std::string& scales, const std::string& biases) {
  return "PTM_1.2\nPTM_FORMAT_LRGB\n2 2\n" + scales + "\n" + biases + "\n" +
         std::string(2 * 2 * 9, 'x');
}

std::string Relight(const Workspace& w, const std::string& ptm_text) {
  WriteText(w.dir() / "bad.ptm", ptm_text);
  return "relight --ptm " + w("bad.ptm") + " --light 0,0,1 --out " + w("relit.png");
}

std::vector<BadInput> Catalogue() {
  const std::string ok_scales = "1 1 1 1 1 1", ok_biases = "0 0 0 0 0 0";
  return {
      // Meshes: the headers that crashed or hung OpenMesh's PLY reader, and sizes
      // that pass a reader and explode later.
      {"PlyPropertyBeforeElement",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply", std::string(kPlyHead) + "property float x\nend_header\n");
       },
       1, "m.ply", "out.json"},
      {"PlyElementWithoutCount",
       [](const Workspace& w) {
         return InspectMesh(
             w, "m.ply", std::string(kPlyHead) + "element vertex\nproperty float x\nend_header\n");
       },
       1, "m.ply", "out.json"},
      {"PlyElementWithoutNameOrCount",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply", std::string(kPlyHead) + "element\nend_header\n");
       },
       1, "m.ply", "out.json"},
      {"PlyCutInsideItsHeader",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply", std::string(kPlyHead) + "element vertex 3\nproper");
       },
       1, "m.ply", "out.json"},
      {"PlyTypoInTheFaceProperty",
       [](const Workspace& w) {
         return InspectMesh(
             w, "m.ply",
             std::string(kPlyHead) +
                 "element vertex 1\nproperty float x\nproperty float y\n"
                 "property float z\nelement face 1\n"
                 "property lsit uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 0\n");
       },
       1, "m.ply", "out.json"},
      {"PlyAnnouncingTwoBillionVertices",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply",
                            std::string(kPlyHead) +
                                "element vertex 2000000000\nproperty float x\nproperty float y\n"
                                "property float z\nend_header\n0 0 0\n");
       },
       1, "m.ply", "out.json"},
      {"PlyWithANanVertex",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply",
                            std::string(kPlyHead) +
                                "element vertex 3\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\n"
                                "property list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n");
       },
       1, "m.ply", "out.json"},
      {"EmptyPly", [](const Workspace& w) { return InspectMesh(w, "m.ply", ""); }, 1, "m.ply",
       "out.json"},
      {"OffAnnouncingTwoBillionVertices",
       [](const Workspace& w) { return InspectMesh(w, "m.off", "OFF\n2000000000 1 0\n0 0 0\n"); },
       1, "m.off", "out.json"},
      {"ObjWithANumberBeyondDouble",
       [](const Workspace& w) {
         return InspectMesh(w, "m.obj", "v 0 0 1e400\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
       },
       1, "m.obj", "out.json"},
      {"ObjFaceIndexZero",
       [](const Workspace& w) {
         return InspectMesh(w, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
       },
       1, "m.obj", "out.json"},
      {"StlWhoseCountDisagreesWithItsSize",
       [](const Workspace& w) {
         std::string stl(84 + 50, '\0');
         stl[80] = 7;
         return InspectMesh(w, "m.stl", stl);
       },
       1, "m.stl", "out.json"},
      {"MeshOfAnUnknownFormat",
       [](const Workspace& w) { return InspectMesh(w, "m.xyz", "0 0 0\n"); }, 1, "m.xyz",
       "out.json"},
      // COLMAP models.
      {"CameraOfFortyThousandPixelsASide",
       [](const Workspace& w) {
         return WithModel(w, [](sfm::Reconstruction& r) {
           for (auto& [id, camera] : r.cameras) camera.width = camera.height = 40000;
         });
       },
       1, "cameras.bin", "out.json"},
      {"NanTwoDimensionalPoint",
       [](const Workspace& w) {
         return WithModel(w, [](sfm::Reconstruction& r) {
           auto& image = r.images.begin()->second;
           image.points2d.push_back({});
           image.points2d.back().xy = Eigen::Vector2d(std::nan(""), 1.0);
         });
       },
       1, "images.bin", "out.json"},
      {"NanThreeDimensionalPoint",
       [](const Workspace& w) {
         return WithModel(w, [](sfm::Reconstruction& r) {
           sfm::Point3D p;
           p.point3d_id = sfm::Point3DId(999999);
           p.xyz = Eigen::Vector3d(std::nan(""), 0, 0);
           r.points3d[p.point3d_id] = p;
         });
       },
       1, "points3D.bin", "out.json"},
      {"ImageNameLeavingTheImagesFolder",
       [](const Workspace& w) {
         return WithModel(w, [](sfm::Reconstruction& r) {
           r.images.begin()->second.name = "../../../../etc/passwd";
         });
       },
       1, "images.bin", "out.json"},
      {"TruncatedCamerasText",
       [](const Workspace& w) {
         const std::string text = ReadText(w.dir() / "sparse_txt/cameras.txt");
         WriteText(w.dir() / "sparse_txt/cameras.txt", text.substr(0, text.size() - 12));
         return "inspect --model " + w("sparse_txt") + " --json " + w("out.json");
       },
       1, "cameras.txt", "out.json"},
      // Lights.
      {"LightsWithANumberBeyondDouble",
       [](const Workspace& w) {
         WriteText(w.dir() / "lights.json",
                   R"({"images": {"x.png": [{"direction": [1e400, 0, 1]}]}})");
         return "inspect --model " + w("sparse") + " --lights " + w("lights.json") + " --json " +
                w("out.json");
       },
       1, "lights.json", "out.json"},
      {"LightsThatAreNotJson",
       [](const Workspace& w) {
         WriteText(w.dir() / "lights.json", "{\"images\": ");
         return "inspect --model " + w("sparse") + " --lights " + w("lights.json") + " --json " +
                w("out.json");
       },
       1, "lights.json", "out.json"},
      // PTM files.
      {"PtmScaleOfTenToThe300",
       [ok_biases](const Workspace& w) {
         return Relight(w, PtmText("1e300 1 1 1 1 1", ok_biases));
       },
       1, "bad.ptm", "relit.png"},
      {"PtmBiasOfTenToTheTwelve",
       [ok_scales](const Workspace& w) {
         return Relight(w, PtmText(ok_scales, "1000000000000 0 0 0 0 0"));
       },
       1, "bad.ptm", "relit.png"},
      {"PtmCutInItsPayload",
       [ok_scales, ok_biases](const Workspace& w) {
         return Relight(w, PtmText(ok_scales, ok_biases).substr(0, 60));
       },
       1, "bad.ptm", "relit.png"},
      {"RelightToAnUnknownImageFormat",
       [](const Workspace& w) {
         return "relight --ptm " + w("sample.ptm") + " --light 0,0,1 --out " + w("relit.xyz");
       },
       2, "relit.xyz", "relit.xyz"},
      // Model folders: names in the manifest stay inside the folder.
      {"ManifestAtlasLeavingTheFolder",
       [](const Workspace& w) {
         return RenderModel(w, Manifest("../../../../../../etc/passwd"), kGoodObj);
       },
       1, "manifest.json", "render"},
      {"ManifestAtlasWithAnAbsolutePath",
       [](const Workspace& w) { return RenderModel(w, Manifest("/etc/passwd"), kGoodObj); }, 1,
       "manifest.json", "render"},
      {"ManifestThatIsNotJson",
       [](const Workspace& w) { return RenderModel(w, "{\"format\": ", kGoodObj); }, 1,
       "manifest.json", "render"},
      {"ModelTextureCoordinateOfTenToThe300",
       [](const Workspace& w) {
         std::string obj = kGoodObj;
         obj.replace(obj.find("vt 1 0"), 6, "vt 1e300 0");
         return RenderModel(w, Manifest("a.exr"), obj);
       },
       1, "model.obj", "render"},
      // BTF captures: the file pattern is never a format string.
      {"BtfPatternWithPercentN", [](const Workspace& w) { return Btf(w, "%n%n"); }, 1, "btf.json",
       "btf_out"},
      {"BtfPatternWithPercentS", [](const Workspace& w) { return Btf(w, "%s_%d_%d.png"); }, 1,
       "btf.json", "btf_out"},
      {"BtfPatternLeavingTheFolder", [](const Workspace& w) { return Btf(w, "../v%d_l%d.png"); }, 1,
       "btf.json", "btf_out"},
      // Absurd settings.
      {"UnconstrainedSynthesisOfABillionTexels",
       [](const Workspace& w) {
         return "synth2d --sample " + w("sample.ptm") +
                " --unconstrained --width 1000000000 "
                "--height 16 --out " +
                w("synth2d_out");
       },
       2, "width", "synth2d_out"},
      // More meshes.
      {"PlyBinaryBodyCutShort",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply",
                            std::string("ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                                        "property float x\nproperty float y\nproperty float z\n"
                                        "end_header\n") +
                                std::string(20, '\0'));
       },
       1, "m.ply", "out.json"},
      {"PlyListCountBeyondTheFile",
       [](const Workspace& w) {
         std::string ply =
             "ply\nformat binary_little_endian 1.0\nelement face 1\n"
             "property list uint int vertex_indices\nelement vertex 0\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n";
         ply += std::string("\xff\xff\xff\x7f", 4) + std::string(12, '\0');
         return InspectMesh(w, "m.ply", ply);
       },
       1, "m.ply", "out.json"},
      {"PlyUnknownPropertyType",
       [](const Workspace& w) {
         return InspectMesh(
             w, "m.ply",
             std::string(kPlyHead) + "element vertex 1\nproperty float128 x\nend_header\n");
       },
       1, "m.ply", "out.json"},
      {"PlyWithoutAFormatLine",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply", "ply\nelement vertex 0\nproperty float x\nend_header\n");
       },
       1, "m.ply", "out.json"},
      {"PlyFaceNamingAMissingVertex",
       [](const Workspace& w) {
         return InspectMesh(w, "m.ply",
                            std::string(kPlyHead) +
                                "element vertex 3\nproperty float x\nproperty float y\n"
                                "property float z\nelement face 1\n"
                                "property list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
       },
       1, "m.ply", "out.json"},
      {"PlyHeaderWithoutEndInItsFirst64KiB",
       [](const Workspace& w) {
         std::string ply = kPlyHead;
         while (ply.size() < 70000) ply += "comment padding padding padding padding\n";
         return InspectMesh(w, "m.ply", ply);
       },
       1, "m.ply", "out.json"},
      {"ObjFaceBeyondItsVertices",
       [](const Workspace& w) {
         return InspectMesh(w, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
       },
       1, "m.obj", "out.json"},
      {"ObjWithoutFaces",
       [](const Workspace& w) { return InspectMesh(w, "m.obj", "v 0 0 0\nv 1 0 0\n"); }, 1, "m.obj",
       "out.json"},
      {"OffCutBeforeItsFaces",
       [](const Workspace& w) {
         return InspectMesh(w, "m.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
       },
       1, "m.off", "out.json"},
      {"OffFaceListingFewerCornersThanItSays",
       [](const Workspace& w) {
         return InspectMesh(w, "m.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n5 0 1 2\n");
       },
       1, "m.off", "out.json"},
      {"StlFacetWithTwoVertices",
       [](const Workspace& w) {
         return InspectMesh(w, "m.stl",
                            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 0\nendloop\nendfacet\nendsolid s\n");
       },
       1, "m.stl", "out.json"},
      {"MeshThatIsAFolder",
       [](const Workspace& w) {
         std::filesystem::create_directories(w.dir() / "m.ply");
         return "inspect --model " + w("sparse") + " --mesh " + w("m.ply") + " --json " +
                w("out.json");
       },
       1, "m.ply", "out.json"},
      // More COLMAP models.
      {"CamerasBinaryCutShort",
       [](const Workspace& w) {
         const std::string bytes = ReadText(w.dir() / "sparse/cameras.bin");
         WriteText(w.dir() / "sparse/cameras.bin", bytes.substr(0, bytes.size() - 5));
         return "inspect --model " + w("sparse") + " --json " + w("out.json");
       },
       1, "cameras.bin", "out.json"},
      {"ImagesBinaryAnnouncingAnAbsurdCount",
       [](const Workspace& w) {
         std::string bytes = ReadText(w.dir() / "sparse/images.bin");
         bytes.replace(0, 8, std::string("\xff\xff\xff\xff\xff\xff\xff\x0f", 8));
         WriteText(w.dir() / "sparse/images.bin", bytes);
         return "inspect --model " + w("sparse") + " --json " + w("out.json");
       },
       1, "images.bin", "out.json"},
      {"UnknownCameraModel",
       [](const Workspace& w) {
         std::string text = ReadText(w.dir() / "sparse_txt/cameras.txt");
         for (const char* model : {"PINHOLE", "OPENCV", "SIMPLE_RADIAL", "SIMPLE_PINHOLE"}) {
           const std::size_t at = text.find(std::string(" ") + model + " ");
           if (at != std::string::npos)
             text.replace(at + 1, std::string(model).size(), "FISHEYE_X");
         }
         WriteText(w.dir() / "sparse_txt/cameras.txt", text);
         return "inspect --model " + w("sparse_txt") + " --json " + w("out.json");
       },
       1, "cameras.txt", "out.json"},
      {"Points3DTextWithAWord",
       [](const Workspace& w) {
         WriteText(w.dir() / "sparse_txt/points3D.txt", "1 0 0 zero 255 255 255 0\n");
         return "inspect --model " + w("sparse_txt") + " --json " + w("out.json");
       },
       1, "points3D.txt", "out.json"},
      {"ImageNameThatIsAbsolute",
       [](const Workspace& w) {
         return WithModel(
             w, [](sfm::Reconstruction& r) { r.images.begin()->second.name = "/etc/passwd"; });
       },
       1, "images.bin", "out.json"},
      {"ModelFolderWithoutAModel",
       [](const Workspace& w) {
         std::filesystem::create_directories(w.dir() / "empty");
         return "inspect --model " + w("empty") + " --json " + w("out.json");
       },
       1, "empty", "out.json"},
      // More lights.
      {"LightsWithAZeroDirection",
       [](const Workspace& w) {
         WriteText(
             w.dir() / "lights.json",
             R"({"images": {"image_000.png": [{"type": "directional", "direction": [0, 0, 0]}]}})");
         return "inspect --model " + w("sparse") + " --lights " + w("lights.json") + " --json " +
                w("out.json");
       },
       1, "lights.json", "out.json"},
      {"LpWithAMissingCoordinate",
       [](const Workspace& w) {
         WriteText(w.dir() / "photos/lights.lp", "2\na.png 0 0\nb.png 0 0 1\n");
         return "fit --images " + w("photos") + " --lights " + w("photos/lights.lp") + " --out " +
                w("fit.ptm");
       },
       1, "lights.lp", "fit.ptm"},
      {"LpAnnouncingMoreLinesThanItHas",
       [](const Workspace& w) {
         WriteText(w.dir() / "photos/lights.lp", "2000000000\na.png 0 0 1\n");
         return "fit --images " + w("photos") + " --lights " + w("photos/lights.lp") + " --out " +
                w("fit.ptm");
       },
       1, "lights.lp", "fit.ptm"},
      {"FitIntoAFolderThatDoesNotExist",
       [](const Workspace& w) {
         // The damaged .lp is never read: the output is checked before the work.
         WriteText(w.dir() / "photos/lights.lp", "2000000000\na.png 0 0 1\n");
         return "fit --images " + w("photos") + " --lights " + w("photos/lights.lp") + " --out " +
                w("no_such_folder/fit.ptm");
       },
       1, "no_such_folder does not exist", "no_such_folder"},
      // More PTM and EXR files.
      {"PtmOfAnUnknownFormat",
       [ok_scales, ok_biases](const Workspace& w) {
         std::string text = PtmText(ok_scales, ok_biases);
         text.replace(text.find("PTM_FORMAT_LRGB"), 15, "PTM_FORMAT_JPEG_XYZ");
         return Relight(w, text);
       },
       1, "bad.ptm", "relit.png"},
      {"PtmOfAHundredThousandTexelsASide",
       [ok_scales, ok_biases](const Workspace& w) {
         std::string text = PtmText(ok_scales, ok_biases);
         text.replace(text.find("2 2"), 3, "100000 100000");
         return Relight(w, text);
       },
       1, "bad.ptm", "relit.png"},
      {"ExrThatIsNotAnImage",
       [](const Workspace& w) {
         WriteText(w.dir() / "bad.exr", "not an exr at all");
         return "relight --ptm " + w("bad.exr") + " --light 0,0,1 --out " + w("relit.png");
       },
       1, "bad.exr", "relit.png"},
      // More model folders.
      {"ManifestWithoutAtlases",
       [](const Workspace& w) {
         return RenderModel(w, R"({"format": "texlume-model"})", kGoodObj);
       },
       1, "manifest.json", "render"},
      {"ManifestAtlasThatIsANumber",
       [](const Workspace& w) {
         return RenderModel(w, R"({"format": "texlume-model", "atlases": [{"exr": 7}]})", kGoodObj);
       },
       1, "manifest.json", "render"},
      {"ModelObjFaceBeyondItsVertices",
       [](const Workspace& w) {
         std::string obj = kGoodObj;
         obj.replace(obj.find("f 1/1 2/2 3/3"), 13, "f 1/1 2/2 9/3");
         return RenderModel(w, Manifest("a.exr"), obj);
       },
       1, "model.obj", "render"},
      // More BTF captures.
      {"BtfPatternWithOneField", [](const Workspace& w) { return Btf(w, "v%d.png"); }, 1,
       "btf.json", "btf_out"},
      {"BtfPatternWithAWideField", [](const Workspace& w) { return Btf(w, "v%099999999d_%d.png"); },
       1, "btf.json", "btf_out"},
      {"BtfWithoutItsImages", [](const Workspace& w) { return Btf(w, "v%02d_l%02d.png"); }, 1,
       "v00_l00.png", "btf_out"},
      // More settings.
      {"RenderWithAHundredSamples",
       [](const Workspace& w) {
         return "render --model " + w("model") + " --cameras " + w("sparse") + " --lights " +
                w("lights.json") + " --out " + w("render") + " --samples 100";
       },
       2, "samples", "render"},
      {"RenderIntoAUsersFolder",
       [](const Workspace& w) {
         // A valid model folder is not needed: the user's folder is refused before rendering
         // would write anything, and the user's file stays.
         std::filesystem::create_directories(w.dir() / "thesis");
         WriteText(w.dir() / "thesis/chapter1.tex", "x");
         RenderModel(w, Manifest("a.exr"), kGoodObj);
         return "render --model " + w("model") + " --cameras " + w("sparse") + " --lights " +
                w("lights.json") + " --out " + w("thesis");
       },
       1, "thesis", "thesis/render.json"},
      {"ObjWhoseExtentOverflows",
       [](const Workspace& w) {
         return InspectMesh(w, "m.obj", "v 1e308 0 0\nv -1e308 0 0\nv 0 1 0\nf 1 2 3\n");
       },
       1, "m.obj", "out.json"},
      {"StlWithANanCorner",
       [](const Workspace& w) {
         return InspectMesh(w, "m.stl",
                            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                            "vertex 1 0 nan\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n");
       },
       1, "m.stl", "out.json"},
      {"ManifestFormatThatIsANumber",
       [](const Workspace& w) {
         return RenderModel(w, R"({"format": 1, "atlases": []})", kGoodObj);
       },
       1, "manifest.json", "render"},
      {"ManifestBakedTextureLeavingTheFolder",
       [](const Workspace& w) {
         const std::string args =
             RenderModel(w,
                         R"({"format": "texlume-model", "atlases": [{"exr": "a.exr"}],
                 "baselines": {"flat_albedo": [0.5, 0.5, 0.5], "baked": ["../../secret.png"]}})",
                         kGoodObj);
         return args + " --baseline baked";
       },
       1, "manifest.json", "render"},
      // Memory: refused up front with the estimate, never ended by the allocator.
      {"MeshLargerThanTheMemoryLimit",
       [](const Workspace& w) {
         return "--memory-limit 1K inspect --model " + w("sparse") + " --mesh " + w("mesh.ply") +
                " --json " + w("out.json");
       },
       1, "mesh.ply", "out.json"},
      {"CameraOfTwentyThousandPixelsASideUnderAOneGigabyteLimit",
       [](const Workspace& w) {
         RenderModel(w, Manifest("a.exr"), kGoodObj);
         WithModel(w, [](sfm::Reconstruction& r) {
           for (auto& [id, camera] : r.cameras) camera.width = camera.height = 15000;
         });
         return "render --memory-limit 1G --model " + w("model") + " --cameras " + w("sparse") +
                " --lights " + w("lights.json") + " --out " + w("render");
       },
       1, "sparse", "render"},
      {"MemoryLimitThatIsNotASize",
       [](const Workspace& w) {
         return "--memory-limit 12Q inspect --model " + w("sparse") + " --json " + w("out.json");
       },
       2, "--memory-limit", "out.json"},
      {"WorldUnitThatIsNotALength",
       [](const Workspace& w) {
         return "synth --model " + w("sparse") + " --images " + w("photos") + " --lights " +
                w("lights.json") + " --mesh " + w("mesh.ply") + " --sample " + w("sample.ptm") +
                " --sample-texel-size 0.01 --world-unit 3parsec --out " + w("model");
       },
       2, "--world-unit", "model"},
      {"SphereCircleOfTenToThe308",
       [](const Workspace& w) {
         return "lights-from-sphere --images " + w("photos") +
                " --circle 1e308,1e308,1e308 --out " + w("lights.lp");
       },
       2, "circle", "lights.lp"},
  };
}

class BadInputTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputTest, EndsWithAClearErrorAndLeavesNothing) {
  const BadInput& c = GetParam();
  TempDir tmp;
  const Workspace w(tmp.path());
  const std::string args = c.prepare(w);
  std::string out;
  const int exit_code = RunCommand(std::string(TEXLUME_BINARY) + " " + args, &out);
  EXPECT_EQ(exit_code, c.exit_code) << args << "\n" << out;
  // TEXLUME_SHOW_MESSAGES=1 prints the table of cases and messages (docs/robustness.md).
  if (std::getenv("TEXLUME_SHOW_MESSAGES")) {
    std::cout << "| " << c.name << " | " << exit_code << " | " << out.substr(0, out.find('\n'))
              << " |\n";
  }
  EXPECT_NE(out.find(c.named), std::string::npos) << args << "\n" << out;
  EXPECT_EQ(out.find("terminate called"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(tmp / c.output)) << c.output;
  for (const auto& entry : fs::recursive_directory_iterator(tmp.path())) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.find(".partial-"), std::string::npos) << entry.path();
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << entry.path();
  }
}

INSTANTIATE_TEST_SUITE_P(Catalogue, BadInputTest, ::testing::ValuesIn(Catalogue()),
                         [](const ::testing::TestParamInfo<BadInput>& param_info) {
                           return param_info.param.name;
                         });

}  // namespace
}  // namespace texlume
