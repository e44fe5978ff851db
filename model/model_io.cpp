#include "model/model_io.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/check.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/partial_output.h"
#include "model/glb_writer.h"
#include "model/packed_textures.h"
#include "ptm/ptm_io.h"
#include "synth/mesh_synthesis.h"

namespace texlume::model {
namespace fs = std::filesystem;
namespace {

constexpr const char* kManifestFormat = "texlume-model";
// How far outside [0, 1] a model folder's texture coordinate may round.
constexpr double kTexcoordSlack = 1e-3;

void WriteObj(const fs::path& path, const TexturedModel& model) {
  std::ofstream out(path);
  out << "# texlume relightable model: base colour textures per atlas; the PTM atlases are\n"
         "# listed in manifest.json (tangent frame x = dP/du, y = dP/dv, z = face normal)\n";
  out << "mtllib model.mtl\n";
  char line[128];
  for (const Eigen::Vector3d& v : model.mesh.vertices) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
    out << line;
  }
  // Smooth normals, one per vertex (vn k belongs to v k).
  for (const Eigen::Vector3d& n : mesh::VertexNormals(model.mesh)) {
    std::snprintf(line, sizeof line, "vn %.6f %.6f %.6f\n", n.x(), n.y(), n.z());
    out << line;
  }
  for (std::size_t f = 0; f < model.mesh.faces.size(); ++f) {
    const ptm::Ptm& atlas = model.atlases[static_cast<std::size_t>(model.face_atlas[f])];
    for (const Eigen::Vector2f& c : model.corner_px[f]) {
      std::snprintf(line, sizeof line, "vt %.9g %.9g\n", c.x() / atlas.width,
                    1.0 - c.y() / atlas.height);
      out << line;
    }
  }
  for (std::size_t a = 0; a < model.atlases.size(); ++a) {
    out << "usemtl atlas_" << a << "\n";
    for (std::size_t f = 0; f < model.mesh.faces.size(); ++f) {
      if (model.face_atlas[f] != static_cast<int>(a)) continue;
      out << "f";
      for (int k = 0; k < 3; ++k) {
        const int v = model.mesh.faces[f][static_cast<std::size_t>(k)] + 1;
        out << " " << v << "/" << f * 3 + k + 1 << "/" << v;
      }
      out << "\n";
    }
  }
  out.close();
  if (!out) throw InputError(path.string(), "cannot be written (disk full?)");
}

nlohmann::json Rows(const Eigen::Matrix4d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

nlohmann::json GltfFrameJson(const TexturedModel& model) {
  const Eigen::Vector3d& up = model.orientation.up;
  const Eigen::Vector3d& front = model.orientation.front;
  return {{"up_in_model", {up.x(), up.y(), up.z()}},
          {"front_in_model", {front.x(), front.y(), front.z()}},
          {"gltf_from_model", Rows(GltfFromModel(model))},
          {"meaning",
           "model.glb's node matrix (rows here): glTF's +Y is up_in_model (up as the "
           "photos were taken), +Z front_in_model (toward the photos), the lowest point at Y = 0; "
           "model.obj keeps the model's (COLMAP's) frame"}};
}

// A unit direction the manifest records as [x, y, z]; InputError naming it otherwise.
Eigen::Vector3d DirectionFromJson(const nlohmann::json& value, const std::string& file,
                                  const std::string& key) {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  if (value.is_array() && value.size() == 3) {
    for (int k = 0; k < 3; ++k)
      d[k] = value[static_cast<std::size_t>(k)].is_number()
                 ? value[static_cast<std::size_t>(k)].get<double>()
                 : NAN;
  }
  if (!d.allFinite() || std::abs(d.norm() - 1.0) > 1e-3)
    throw InputError(file, "gltf_frame: " + key + " is not a unit vector [x, y, z]");
  return d;
}

}  // namespace

cv::Mat BaseColourImage(const ptm::Ptm& ptm) {
  const std::vector<float> rgb = ptm::Relight(ptm, Eigen::Vector3d::UnitZ());
  cv::Mat out(ptm.height, ptm.width, CV_8UC3);
  for (int y = 0; y < ptm.height; ++y)
    for (int x = 0; x < ptm.width; ++x)
      for (int c = 0; c < 3; ++c)
        out.at<cv::Vec3b>(y, x)[2 - c] = cv::saturate_cast<std::uint8_t>(
            255.0f *
            rgb[(static_cast<std::size_t>(y) * ptm.width + x) * 3 + static_cast<std::size_t>(c)]);
  return out;
}

cv::Mat NormalMapImage(const ptm::Ptm& ptm) {
  const std::vector<float> normals = ptm::NormalMap(ptm);
  cv::Mat out(ptm.height, ptm.width, CV_8UC3);
  for (int y = 0; y < ptm.height; ++y) {
    for (int x = 0; x < ptm.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * ptm.width + x;
      for (int c = 0; c < 3; ++c)
        out.at<cv::Vec3b>(y, x)[2 - c] = cv::saturate_cast<std::uint8_t>(
            127.5f * (normals[t * 3 + static_cast<std::size_t>(c)] + 1.0f));
    }
  }
  return out;
}

cv::Mat AlbedoImage(const ptm::Ptm& ptm) {
  const std::vector<float> rgb = ptm::Relight(ptm, Eigen::Vector3d::UnitZ());
  const std::vector<float> normals = ptm::NormalMap(ptm);
  cv::Mat out(ptm.height, ptm.width, CV_8UC3);
  for (int y = 0; y < ptm.height; ++y) {
    for (int x = 0; x < ptm.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * ptm.width + x;
      // Lambert under a head-on light: I = albedo * n_z (linear domain).
      const float nz = std::max(0.2f, normals[t * 3 + 2]);
      for (int c = 0; c < 3; ++c)
        out.at<cv::Vec3b>(y, x)[2 - c] = cv::saturate_cast<std::uint8_t>(
            255.0f * LinearToSrgb(SrgbToLinear(rgb[t * 3 + static_cast<std::size_t>(c)]) / nz));
    }
  }
  return out;
}

namespace {

// The model folder's files, written into the temporary folder `tmp` (WriteModelFolder):
// the atlases first, then the meshes that name them, the manifest last.
class ModelFolderWriter {
 public:
  ModelFolderWriter(const TexturedModel& model, const fs::path& tmp, const nlohmann::json& record)
      : model_(model), tmp_(tmp), manifest_(record) {
    manifest_["format"] = kManifestFormat;
    manifest_["version"] = 1;
    manifest_["mesh"] = {{"obj", "model.obj"},
                         {"mtl", "model.mtl"},
                         {"glb", "model.glb"},
                         {"vertices", model.mesh.vertices.size()},
                         {"faces", model.mesh.faces.size()}};
    manifest_["ptm_frame"] =
        "per texel: x = dP/du, y = dP/dv (v up, as in OBJ), z = face normal; light directions "
        "point from the surface to the light";
    manifest_["ptm_evaluation"] = {
        {"domain", "display (sRGB-encoded); several lights sum in the linear domain"},
        {"horizon_elevation_deg", ptm::kHorizonElevationDeg},
        {"below_horizon_elevation",
         "value at horizon_elevation_deg (same azimuth) times l_z / sin(horizon_elevation_deg)"},
        {"light_response", LightResponseJson(model.light_response)}};
    if (!model.shadowing.empty())
      manifest_["ptm_evaluation"]["self_shadowing"] =
          "per atlas, \"horizon\": the relief's horizon per texel (channels horizon.SS: "
          "elevation in radians at azimuth 2 pi SS / sectors from x towards y); each light's "
          "linear contribution times v + (1 - v) texlume:shadow_floor, v rising linearly from 0 "
          "to 1 across texlume:penumbra_rad about the horizon (the ambient term unshadowed)";
    manifest_["gltf_frame"] = GltfFrameJson(model);
    manifest_["atlases"] = nlohmann::json::array();
    mtl_ << "# texlume: albedo and normal map from the PTM atlases (model.glb carries them too)\n";
  }

  // Per atlas: its pictures, the PTM and EXR, its manifest entry, MTL material and GLB data.
  void WriteAtlases() {
    for (std::size_t a = 0; a < model_.atlases.size(); ++a) WriteAtlas(a);
  }

  // model.mtl, model.obj and model.glb.
  void WriteMeshes() {
    const std::string mtl = mtl_.str();
    WriteFileAtomically(
        tmp_ / "model.mtl", [&](std::ostream& o) { o << mtl; }, false);
    WriteObj(tmp_ / "model.obj", model_);
    WriteGlb(tmp_ / "model.glb", model_, glb_atlases_);
  }

  // The manifest, listing every file in the folder; last, so that a folder with a
  // manifest is a finished model.
  void WriteManifest() {
    nlohmann::json files = nlohmann::json::array();
    for (const auto& entry : fs::recursive_directory_iterator(tmp_))
      if (entry.is_regular_file()) files.push_back(entry.path().lexically_relative(tmp_).string());
    files.push_back("manifest.json");
    std::sort(files.begin(), files.end());
    manifest_["files"] = files;
    WriteFileAtomically(
        tmp_ / "manifest.json", [&](std::ostream& o) { o << manifest_.dump(2) << "\n"; }, false);
  }

 private:
  void WriteAtlas(std::size_t a) {
    const ptm::Ptm& atlas = model_.atlases[a];
    const std::string k = std::to_string(a);
    const std::string base = "base_colour_" + k + ".png", albedo = "albedo_" + k + ".png";
    const std::string normal = "normal_" + k + ".png";
    const std::string ptm_file = "ptm_atlas_" + k + ".ptm", exr_file = "ptm_atlas_" + k + ".exr";
    GlbAtlas& glb = glb_atlases_.emplace_back();
    WriteBytesAtomically(tmp_ / base, EncodePng(BaseColourImage(atlas), base));
    glb.albedo_png = EncodePng(AlbedoImage(atlas), albedo);
    WriteBytesAtomically(tmp_ / albedo, glb.albedo_png);
    glb.normal_png = EncodePng(NormalMapImage(atlas), normal);
    WriteBytesAtomically(tmp_ / normal, glb.normal_png);
    ptm::WritePtmFile(atlas, tmp_ / ptm_file);
    ptm::WritePtmExr(atlas, tmp_ / exr_file);
    const std::string format = atlas.format == ptm::PtmFormat::kLrgb ? "LRGB" : "RGB";
    manifest_["atlases"].push_back({{"ptm", ptm_file},
                                    {"exr", exr_file},
                                    {"base_colour", base},
                                    {"albedo", albedo},
                                    {"normal", normal},
                                    {"width", atlas.width},
                                    {"height", atlas.height},
                                    {"format", format}});
    if (!model_.shadowing.empty()) {
      TEXLUME_CHECK(model_.shadowing.size() == model_.atlases.size() &&
                        model_.shadowing[a].horizon.width == atlas.width &&
                        model_.shadowing[a].horizon.height == atlas.height,
                    "one horizon map of its atlas's size per atlas");
      const std::string horizon_file = "horizon_atlas_" + k + ".exr";
      ptm::WriteSelfShadowingExr(model_.shadowing[a], tmp_ / horizon_file);
      manifest_["atlases"].back()["horizon"] = horizon_file;
      HorizonTextures horizon =
          EncodeHorizonTextures(model_.shadowing[a], "the GLB's horizon of atlas " + k);
      glb.horizon_pngs = std::move(horizon.pngs);
      glb.horizon_fields = std::move(horizon.fields);
    }
    const nlohmann::json ptm_fields = {
        {"format", format},
        {"frame", manifest_["ptm_frame"]},
        {"evaluation", manifest_["ptm_evaluation"]},
        {"texcoord", "TEXCOORD_0 (glTF v down; the PTM's y axis points to -v)"}};
    glb.extras = {{"texlume_ptm", ptm_fields}};
    glb.extras["texlume_ptm"]["ptm"] = ptm_file;
    glb.extras["texlume_ptm"]["exr"] = exr_file;
    const ptm::WebPlanes web = ptm::QuantiseWebPlanes(atlas);
    for (const cv::Mat& plane : web.images)
      glb.ptm_plane_pngs.push_back(EncodePng(plane, "a PTM plane of " + ptm_file));
    glb.ptm_fields = ptm_fields;
    glb.ptm_fields.update(web.Info());
    glb.ptm_fields["plane_order"] =
        "relight's web format: value = (byte / 255 - bias) * scale per plane; planes "
        "(1, u, v, u^2, uv, v^2), after R, G, B for LRGB, per channel for RGB";
    // The albedo under the relief: norm (MTL's PBR extension) and map_Bump (which
    // Blender reads as a normal map) give the normal map.
    mtl_ << "newmtl atlas_" << k << "\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " << albedo
         << "\nnorm " << normal << "\nmap_Bump " << normal << "\n# head-on base colour: " << base
         << "; PTM: " << ptm_file << " (lossless " << exr_file << ")\n\n";
  }

  const TexturedModel& model_;
  const fs::path tmp_;
  nlohmann::json manifest_;
  std::ostringstream mtl_;
  std::vector<GlbAtlas> glb_atlases_;
};

}  // namespace

void WriteModelFolder(const fs::path& dir, const TexturedModel& model, const nlohmann::json& record,
                      const std::vector<std::pair<std::string, cv::Mat>>& extra_images,
                      const std::function<void(const fs::path&)>& write_more) {
  RequireReplaceableFolder(dir, "manifest.json", "a texlume model folder");
  PartialOutput output(dir, PartialOutput::Kind::kFolder);
  {
    ModelFolderWriter writer(model, output.path(), record);
    writer.WriteAtlases();
    writer.WriteMeshes();
    for (const auto& [name, image] : extra_images)
      WriteBytesAtomically(output.path() / name, EncodePng(image, name));
    if (write_more) write_more(output.path());
    writer.WriteManifest();
  }
  output.Commit();
}

std::string ManifestFileName(const nlohmann::json& value, const fs::path& dir,
                             const std::string& key) {
  const std::string label = (dir / "manifest.json").string();
  if (!value.is_string()) throw InputError(label, "\"" + key + "\" is not a file name");
  const std::string name = value.get<std::string>();
  ContainedPath(dir, name, label, key);
  return name;
}

nlohmann::json ReadModelManifest(const fs::path& dir) {
  const fs::path manifest_path = dir / "manifest.json";
  const nlohmann::json manifest = ReadJsonFile(manifest_path);
  if (!manifest.is_object() || !manifest.contains("format") || !manifest["format"].is_string() ||
      manifest["format"].get<std::string>() != kManifestFormat || !manifest.contains("atlases") ||
      !manifest["atlases"].is_array())
    throw InputError(manifest_path.string(), "is not a texlume model manifest");
  return manifest;
}

Eigen::Matrix3d AtlasFaceFrame(const TexturedModel& model, std::size_t f) {
  const mesh::TriangleMesh& mesh = model.mesh;
  const Eigen::Vector3d e1 = mesh.Corner(f, 1) - mesh.Corner(f, 0);
  const Eigen::Vector3d e2 = mesh.Corner(f, 2) - mesh.Corner(f, 0);
  const Eigen::Vector3d n = e1.cross(e2).normalized();
  Eigen::Vector3d x = e1;
  if (f < model.corner_px.size()) {
    const auto& c = model.corner_px[f];
    // v up: dv = -dy.
    const double du1 = c[1].x() - c[0].x(), dv1 = -(c[1].y() - c[0].y());
    const double du2 = c[2].x() - c[0].x(), dv2 = -(c[2].y() - c[0].y());
    const double det = du1 * dv2 - du2 * dv1;
    if (std::abs(det) > 1e-12) x = (e1 * dv2 - e2 * dv1) / det;  // dP/du
  }
  x = (x - n * n.dot(x)).normalized();
  Eigen::Matrix3d frame;
  frame.col(0) = x;
  frame.col(1) = n.cross(x);
  frame.col(2) = n;
  return frame;
}

void ForEachCornerByAtlas(const TexturedModel& model,
                          const std::function<void(const ModelCorner&)>& visit) {
  TEXLUME_CHECK(model.corner_px.size() == model.mesh.faces.size() &&
                    model.face_atlas.size() == model.mesh.faces.size(),
                "texture coordinates and an atlas for every face");
  for (const int a : model.face_atlas)
    TEXLUME_CHECK(a >= 0 && static_cast<std::size_t>(a) < model.atlases.size(),
                  "every face's atlas exists");
  std::vector<std::size_t> order(model.mesh.faces.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return model.face_atlas[a] < model.face_atlas[b];
  });
  const std::vector<Eigen::Vector3d> vertex_normals = mesh::VertexNormals(model.mesh);
  ModelCorner corner;
  for (const std::size_t f : order) {
    corner.face = f;
    corner.atlas = model.face_atlas[f];
    corner.frame = AtlasFaceFrame(model, f);
    const ptm::Ptm& atlas = model.atlases[static_cast<std::size_t>(corner.atlas)];
    for (std::size_t k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(model.mesh.faces[f][k]);
      corner.position = model.mesh.vertices[v];
      corner.smooth_normal = vertex_normals[v];
      const Eigen::Vector2f& px = model.corner_px[f][k];
      corner.uv_down = Eigen::Vector2f(px.x() / static_cast<float>(atlas.width),
                                       px.y() / static_cast<float>(atlas.height));
      visit(corner);
    }
  }
}

nlohmann::json LightResponseJson(const ptm::LightResponse& response) {
  std::vector<double> elevations;
  for (int k = 0; k < ptm::LightResponse::kKnots; ++k)
    elevations.push_back(k * ptm::LightResponse::kKnotSpacingDeg);
  return {{"elevations_deg", elevations},
          {"factors", response.elevation_factor},
          {"ambient", response.ambient},
          {"oren_nayar_b_over_a", response.oren_nayar_b_over_a},
          {"meaning",
           "each light's linear value times the factor at its elevation above the texel's "
           "tangent plane (linear between knots) and times 1 + oren_nayar_b_over_a max(0, "
           "cos(phi_r - phi_i)) sin(alpha) tan(beta) (Oren and Nayar 1994: alpha, beta the "
           "larger and the smaller of the light's and the view's angles from the normal, beta "
           "at most 80 degrees; phi their azimuths); plus ambient times the linear value under "
           "a unit light at the zenith"}};
}

ptm::LightResponse LightResponseFromJson(const nlohmann::json& record, const std::string& file) {
  ptm::LightResponse r;
  if (!record.is_object()) throw InputError(file, "light_response is not an object");
  const auto& factors = record.value("factors", nlohmann::json());
  const auto& elevations = record.value("elevations_deg", nlohmann::json());
  if (!factors.is_array() || factors.size() != r.elevation_factor.size() ||
      !elevations.is_array() || elevations.size() != factors.size() ||
      !record.contains("ambient") || !record["ambient"].is_number())
    throw InputError(file, "light_response needs " + std::to_string(r.elevation_factor.size()) +
                               " elevations_deg, as many factors and an ambient");
  for (std::size_t k = 0; k < factors.size(); ++k) {
    if (!factors[k].is_number() || !elevations[k].is_number() ||
        elevations[k].get<double>() != static_cast<double>(k) * ptm::LightResponse::kKnotSpacingDeg)
      throw InputError(file, "light_response: knot " + std::to_string(k) + " is not a number at " +
                                 std::to_string(k * 10) + " degrees");
    r.elevation_factor[k] = factors[k].get<double>();
  }
  r.ambient = record["ambient"].get<double>();
  // Models written before the view term have none.
  if (record.contains("oren_nayar_b_over_a")) {
    if (!record["oren_nayar_b_over_a"].is_number())
      throw InputError(file, "light_response: oren_nayar_b_over_a is not a number");
    r.oren_nayar_b_over_a = record["oren_nayar_b_over_a"].get<double>();
  }
  try {
    r.Check();
  } catch (const OptionError& e) {
    throw InputError(file, e.what());
  }
  return r;
}

TexturedModel ReadModelFolder(const fs::path& dir) {
  const fs::path manifest_path = dir / "manifest.json";
  const nlohmann::json manifest = ReadModelManifest(dir);
  TexturedModel model;
  const auto& evaluation = manifest.value("ptm_evaluation", nlohmann::json());
  if (evaluation.is_object() && evaluation.contains("light_response"))
    model.light_response =
        LightResponseFromJson(evaluation["light_response"], manifest_path.string());
  if (manifest.contains("gltf_frame") && manifest["gltf_frame"].is_object()) {
    const nlohmann::json& frame = manifest["gltf_frame"];
    model.orientation.up = DirectionFromJson(frame.value("up_in_model", nlohmann::json()),
                                             manifest_path.string(), "up_in_model");
    model.orientation.front = DirectionFromJson(frame.value("front_in_model", nlohmann::json()),
                                                manifest_path.string(), "front_in_model");
    if (std::abs(model.orientation.up.dot(model.orientation.front)) > 0.99)
      throw InputError(manifest_path.string(),
                       "gltf_frame: up_in_model and front_in_model are "
                       "(nearly) parallel");
  }
  for (const auto& entry : manifest["atlases"]) {
    if (!entry.is_object() || !entry.contains("exr") || !entry["exr"].is_string())
      throw InputError(manifest_path.string(), "an atlas entry has no \"exr\" file");
    model.atlases.push_back(ptm::ReadPtmExr(dir / ManifestFileName(entry["exr"], dir, "exr")));
    if (!entry.contains("horizon")) continue;
    const fs::path horizon_path = dir / ManifestFileName(entry["horizon"], dir, "horizon");
    model.shadowing.push_back(ptm::ReadSelfShadowingExr(horizon_path, model.atlases.back().width,
                                                        model.atlases.back().height, "its atlas"));
  }
  if (!model.shadowing.empty() && model.shadowing.size() != model.atlases.size())
    throw InputError(manifest_path.string(), "some atlases have a \"horizon\" and some not");
  const fs::path obj_path = dir / "model.obj";
  std::ifstream obj = OpenForReading(obj_path, false);
  std::vector<Eigen::Vector2d> texcoords;
  std::vector<std::array<int, 3>> face_vt;
  int current_atlas = -1;
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(obj, line)) {
    ++line_number;
    std::istringstream s(line);
    std::string tag;
    if (!(s >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      Eigen::Vector3d v;
      if (!(s >> v.x() >> v.y() >> v.z()) || !v.allFinite())
        throw InputError(obj_path.string(), "bad vertex", line_number);
      model.mesh.vertices.push_back(v);
    } else if (tag == "vt") {
      Eigen::Vector2d t;
      if (!(s >> t.x() >> t.y()) || !t.allFinite())
        throw InputError(obj_path.string(), "bad texture coordinate", line_number);
      // texlume writes atlas coordinates in [0, 1]; anything far outside is damage.
      if ((t.array() < -kTexcoordSlack).any() || (t.array() > 1.0 + kTexcoordSlack).any())
        throw InputError(obj_path.string(), "texture coordinate outside the atlas [0, 1]",
                         line_number);
      texcoords.push_back(t);
    } else if (tag == "usemtl") {
      std::string name;
      s >> name;
      if (name.rfind("atlas_", 0) != 0)
        throw InputError(obj_path.string(), "unknown material " + name, line_number);
      try {
        current_atlas = std::stoi(name.substr(6));
      } catch (const std::exception&) {
        current_atlas = -1;
      }
      if (current_atlas < 0 || current_atlas >= static_cast<int>(model.atlases.size()))
        throw InputError(obj_path.string(), "material " + name + " has no atlas in the manifest",
                         line_number);
    } else if (tag == "f") {
      std::array<int, 3> v{}, t{};
      for (int k = 0; k < 3; ++k) {
        std::string corner;
        char slash = 0;
        if (!(s >> corner))
          throw InputError(obj_path.string(), "a face needs 3 corners", line_number);
        std::istringstream cs(corner);
        int normal = 0;
        if (!(cs >> v[static_cast<std::size_t>(k)] >> slash >> t[static_cast<std::size_t>(k)]) ||
            slash != '/' || (cs >> slash && (slash != '/' || !(cs >> normal) || normal < 1)))
          throw InputError(obj_path.string(), "face corners must be v/vt or v/vt/vn", line_number);
        if (v[static_cast<std::size_t>(k)] < 1 ||
            v[static_cast<std::size_t>(k)] > static_cast<int>(model.mesh.vertices.size()) ||
            t[static_cast<std::size_t>(k)] < 1 ||
            t[static_cast<std::size_t>(k)] > static_cast<int>(texcoords.size()))
          throw InputError(obj_path.string(), "face index out of range", line_number);
        --v[static_cast<std::size_t>(k)];
        --t[static_cast<std::size_t>(k)];
      }
      std::string more;
      if (s >> more)
        throw InputError(obj_path.string(), "only triangles are supported", line_number);
      if (current_atlas < 0)
        throw InputError(obj_path.string(), "a face before any usemtl", line_number);
      model.mesh.faces.push_back(v);
      face_vt.push_back(t);
      model.face_atlas.push_back(current_atlas);
    }
  }
  if (model.mesh.faces.empty()) throw InputError(obj_path.string(), "has no faces");
  for (std::size_t f = 0; f < model.mesh.faces.size(); ++f) {
    const ptm::Ptm& atlas = model.atlases[static_cast<std::size_t>(model.face_atlas[f])];
    std::array<Eigen::Vector2f, 3> c;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d& t =
          texcoords[static_cast<std::size_t>(face_vt[f][static_cast<std::size_t>(k)])];
      c[static_cast<std::size_t>(k)] =
          Eigen::Vector2f(static_cast<float>(t.x() * atlas.width),
                          static_cast<float>((1.0 - t.y()) * atlas.height));
    }
    model.corner_px.push_back(c);
  }
  return model;
}

}  // namespace texlume::model
