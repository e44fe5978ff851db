#include "model/model_io.h"

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/partial_output.h"
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
      for (int k = 0; k < 3; ++k)
        out << " " << model.mesh.faces[f][static_cast<std::size_t>(k)] + 1 << "/" << f * 3 + k + 1;
      out << "\n";
    }
  }
  out.close();
  if (!out) throw InputError(path.string(), "cannot be written (disk full?)");
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

void WriteGlb(const fs::path& path, const TexturedModel& model,
              const std::vector<std::vector<unsigned char>>& base_colour_png,
              const std::vector<nlohmann::json>& material_extras) {
  const std::vector<Eigen::Vector3d> normals = mesh::VertexNormals(model.mesh);
  std::vector<unsigned char> bin;
  auto align4 = [&]() {
    while (bin.size() % 4) bin.push_back(0);
  };
  auto append = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    bin.insert(bin.end(), p, p + bytes);
  };
  nlohmann::json gltf;
  gltf["asset"] = {{"version", "2.0"}, {"generator", "texlume"}};
  gltf["scene"] = 0;
  gltf["scenes"] = {{{"nodes", {0}}}};
  gltf["nodes"] = {{{"mesh", 0}, {"name", "model"}}};
  nlohmann::json buffer_views = nlohmann::json::array(), accessors = nlohmann::json::array();
  nlohmann::json primitives = nlohmann::json::array(), materials = nlohmann::json::array();
  nlohmann::json images = nlohmann::json::array(), textures = nlohmann::json::array();
  auto add_view = [&](std::size_t offset, std::size_t length, int target) {
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    if (target) v["target"] = target;
    buffer_views.push_back(v);
    return static_cast<int>(buffer_views.size() - 1);
  };
  for (std::size_t a = 0; a < model.atlases.size(); ++a) {
    // Unshared corners (texture seams everywhere between charts).
    std::vector<float> positions, vertex_normals, uvs;
    std::vector<std::uint32_t> indices;
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), hi = -lo;
    const ptm::Ptm& atlas = model.atlases[a];
    for (std::size_t f = 0; f < model.mesh.faces.size(); ++f) {
      if (model.face_atlas[f] != static_cast<int>(a)) continue;
      for (int k = 0; k < 3; ++k) {
        const int v = model.mesh.faces[f][static_cast<std::size_t>(k)];
        const Eigen::Vector3f p = model.mesh.vertices[static_cast<std::size_t>(v)].cast<float>();
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
        positions.insert(positions.end(), {p.x(), p.y(), p.z()});
        const Eigen::Vector3f n = normals[static_cast<std::size_t>(v)].cast<float>();
        vertex_normals.insert(vertex_normals.end(), {n.x(), n.y(), n.z()});
        const Eigen::Vector2f c = model.corner_px[f][static_cast<std::size_t>(k)];
        uvs.insert(uvs.end(), {c.x() / atlas.width, c.y() / atlas.height});
        indices.push_back(static_cast<std::uint32_t>(indices.size()));
      }
    }
    if (indices.empty()) continue;
    const std::size_t count = indices.size();
    align4();
    const int pos_view = add_view(bin.size(), positions.size() * 4, 34962);
    append(positions.data(), positions.size() * 4);
    const int nrm_view = add_view(bin.size(), vertex_normals.size() * 4, 34962);
    append(vertex_normals.data(), vertex_normals.size() * 4);
    const int uv_view = add_view(bin.size(), uvs.size() * 4, 34962);
    append(uvs.data(), uvs.size() * 4);
    const int idx_view = add_view(bin.size(), indices.size() * 4, 34963);
    append(indices.data(), indices.size() * 4);
    align4();
    const int img_view = add_view(bin.size(), base_colour_png[a].size(), 0);
    append(base_colour_png[a].data(), base_colour_png[a].size());
    const int first = static_cast<int>(accessors.size());
    accessors.push_back({{"bufferView", pos_view},
                         {"componentType", 5126},
                         {"count", count},
                         {"type", "VEC3"},
                         {"min", {lo.x(), lo.y(), lo.z()}},
                         {"max", {hi.x(), hi.y(), hi.z()}}});
    accessors.push_back(
        {{"bufferView", nrm_view}, {"componentType", 5126}, {"count", count}, {"type", "VEC3"}});
    accessors.push_back(
        {{"bufferView", uv_view}, {"componentType", 5126}, {"count", count}, {"type", "VEC2"}});
    accessors.push_back(
        {{"bufferView", idx_view}, {"componentType", 5125}, {"count", count}, {"type", "SCALAR"}});
    images.push_back({{"bufferView", img_view},
                      {"mimeType", "image/png"},
                      {"name", "base_colour_" + std::to_string(a)}});
    textures.push_back({{"source", images.size() - 1}, {"sampler", 0}});
    nlohmann::json material = {{"name", "atlas_" + std::to_string(a)},
                               {"pbrMetallicRoughness",
                                {{"baseColorTexture", {{"index", textures.size() - 1}}},
                                 {"metallicFactor", 0.0},
                                 {"roughnessFactor", 1.0}}}};
    if (a < material_extras.size()) material["extras"] = material_extras[a];
    materials.push_back(material);
    primitives.push_back(
        {{"attributes", {{"POSITION", first}, {"NORMAL", first + 1}, {"TEXCOORD_0", first + 2}}},
         {"indices", first + 3},
         {"material", materials.size() - 1},
         {"mode", 4}});
  }
  align4();
  gltf["meshes"] = {{{"primitives", primitives}, {"name", "model"}}};
  gltf["accessors"] = accessors;
  gltf["bufferViews"] = buffer_views;
  gltf["buffers"] = {{{"byteLength", bin.size()}}};
  gltf["images"] = images;
  gltf["textures"] = textures;
  gltf["samplers"] = {
      {{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 33071}, {"wrapT", 33071}}};
  gltf["materials"] = materials;
  std::string json = gltf.dump();
  while (json.size() % 4) json.push_back(' ');
  const std::uint32_t total =
      12 + 8 + static_cast<std::uint32_t>(json.size()) + 8 + static_cast<std::uint32_t>(bin.size());
  WriteFileAtomically(
      path,
      [&](std::ostream& out) {
        auto u32 = [&](std::uint32_t v) { WriteU32(out, v); };
        u32(0x46546C67);  // "glTF"
        u32(2);
        u32(total);
        u32(static_cast<std::uint32_t>(json.size()));
        u32(0x4E4F534A);  // "JSON"
        out.write(json.data(), static_cast<std::streamsize>(json.size()));
        u32(static_cast<std::uint32_t>(bin.size()));
        u32(0x004E4942);  // "BIN\0"
        out.write(reinterpret_cast<const char*>(bin.data()),
                  static_cast<std::streamsize>(bin.size()));
      },
      true);
}

void WriteModelFolder(const fs::path& dir, const TexturedModel& model, const nlohmann::json& record,
                      const std::vector<std::pair<std::string, cv::Mat>>& extra_images,
                      const std::function<void(const fs::path&)>& write_more) {
  RequireReplaceableFolder(dir, "manifest.json", "a texlume model folder");
  PartialOutput output(dir, PartialOutput::Kind::kFolder);
  const fs::path& tmp = output.path();
  {
    nlohmann::json manifest = record;
    manifest["format"] = kManifestFormat;
    manifest["version"] = 1;
    manifest["mesh"] = {{"obj", "model.obj"},
                        {"mtl", "model.mtl"},
                        {"glb", "model.glb"},
                        {"vertices", model.mesh.vertices.size()},
                        {"faces", model.mesh.faces.size()}};
    manifest["ptm_frame"] =
        "per texel: x = dP/du, y = dP/dv (v up, as in OBJ), z = face normal; light directions "
        "point from the surface to the light";
    manifest["ptm_evaluation"] = {
        {"domain", "display (sRGB-encoded); several lights sum in the linear domain"},
        {"horizon_elevation_deg", ptm::kHorizonElevationDeg},
        {"below_horizon_elevation",
         "value at horizon_elevation_deg (same azimuth) times l_z / sin(horizon_elevation_deg)"},
        {"light_response", LightResponseJson(model.light_response)}};
    manifest["atlases"] = nlohmann::json::array();
    std::vector<std::vector<unsigned char>> pngs;
    std::vector<nlohmann::json> extras;
    std::ofstream mtl(tmp / "model.mtl");
    mtl << "# texlume: base colour = PTM under a head-on light; albedo and PTM atlases alongside\n";
    for (std::size_t a = 0; a < model.atlases.size(); ++a) {
      const std::string k = std::to_string(a);
      const std::string base = "base_colour_" + k + ".png", albedo = "albedo_" + k + ".png";
      const std::string ptm_file = "ptm_atlas_" + k + ".ptm", exr_file = "ptm_atlas_" + k + ".exr";
      pngs.push_back(EncodePng(BaseColourImage(model.atlases[a]), base));
      WriteBytesAtomically(tmp / base, pngs.back());
      WriteBytesAtomically(tmp / albedo, EncodePng(AlbedoImage(model.atlases[a]), albedo));
      ptm::WritePtmFile(model.atlases[a], tmp / ptm_file);
      ptm::WritePtmExr(model.atlases[a], tmp / exr_file);
      const std::string format = model.atlases[a].format == ptm::PtmFormat::kLrgb ? "LRGB" : "RGB";
      nlohmann::json entry = {{"ptm", ptm_file},
                              {"exr", exr_file},
                              {"base_colour", base},
                              {"albedo", albedo},
                              {"width", model.atlases[a].width},
                              {"height", model.atlases[a].height},
                              {"format", format}};
      manifest["atlases"].push_back(entry);
      extras.push_back(
          {{"texlume_ptm",
            {{"ptm", ptm_file},
             {"exr", exr_file},
             {"format", format},
             {"frame", manifest["ptm_frame"]},
             {"evaluation", manifest["ptm_evaluation"]},
             {"texcoord", "TEXCOORD_0 (glTF v down; the PTM's y axis points to -v)"}}}});
      mtl << "newmtl atlas_" << k << "\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " << base
          << "\n# albedo: " << albedo << "; PTM: " << ptm_file << " (lossless " << exr_file
          << ")\n\n";
    }
    mtl.close();
    if (!mtl) throw InputError((dir / "model.mtl").string(), "cannot be written (disk full?)");
    WriteObj(tmp / "model.obj", model);
    WriteGlb(tmp / "model.glb", model, pngs, extras);
    nlohmann::json files = nlohmann::json::array();
    for (const auto& [name, image] : extra_images) {
      WriteBytesAtomically(tmp / name, EncodePng(image, name));
    }
    if (write_more) write_more(tmp);
    for (const auto& entry : fs::recursive_directory_iterator(tmp))
      if (entry.is_regular_file()) files.push_back(entry.path().lexically_relative(tmp).string());
    files.push_back("manifest.json");
    std::sort(files.begin(), files.end());
    manifest["files"] = files;
    // The manifest last: a folder with a manifest is a finished model.
    WriteFileAtomically(
        tmp / "manifest.json", [&](std::ostream& o) { o << manifest.dump(2) << "\n"; }, false);
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

nlohmann::json LightResponseJson(const ptm::LightResponse& response) {
  std::vector<double> elevations;
  for (int k = 0; k < ptm::LightResponse::kKnots; ++k)
    elevations.push_back(k * ptm::LightResponse::kKnotSpacingDeg);
  return {{"elevations_deg", elevations},
          {"factors", response.elevation_factor},
          {"ambient", response.ambient},
          {"meaning",
           "each light's linear value times the factor at its elevation above the texel's "
           "tangent plane (linear between knots); plus ambient times the linear value under a "
           "unit light at the zenith"}};
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
  for (const auto& entry : manifest["atlases"]) {
    if (!entry.is_object() || !entry.contains("exr") || !entry["exr"].is_string())
      throw InputError(manifest_path.string(), "an atlas entry has no \"exr\" file");
    model.atlases.push_back(ptm::ReadPtmExr(dir / ManifestFileName(entry["exr"], dir, "exr")));
  }
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
        if (!(cs >> v[static_cast<std::size_t>(k)] >> slash >> t[static_cast<std::size_t>(k)]) ||
            slash != '/')
          throw InputError(obj_path.string(), "face corners must be v/vt", line_number);
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
