#include "model/glb_writer.h"

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "core/check.h"
#include "core/file_util.h"

namespace texlume::model {
namespace fs = std::filesystem;
namespace {

// glTF's enumerations (glTF 2.0 §5).
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kTriangles = 4;

std::vector<double> ColumnMajor(const Eigen::Matrix4d& m) {
  std::vector<double> out;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out.push_back(m(r, c));
  return out;
}

// One primitive's vertex data: every face corner on its own (charts meet at seams).
struct PrimitiveData {
  std::vector<float> positions, normals, tangents, texcoords;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  std::size_t NumCorners() const { return positions.size() / 3; }
};

// The corners of each atlas's faces (ForEachCornerByAtlas). The tangent is the atlas
// frame's x made orthogonal to the corner's smooth normal; w makes N x T point along the
// frame's y.
std::vector<PrimitiveData> PrimitivesByAtlas(const TexturedModel& model) {
  std::vector<PrimitiveData> primitives(model.atlases.size());
  ForEachCornerByAtlas(model, [&](const ModelCorner& c) {
    PrimitiveData& d = primitives[static_cast<std::size_t>(c.atlas)];
    const Eigen::Vector3f p = c.position.cast<float>();
    d.lo = d.lo.cwiseMin(p);
    d.hi = d.hi.cwiseMax(p);
    d.positions.insert(d.positions.end(), {p.x(), p.y(), p.z()});
    const Eigen::Vector3d& n = c.smooth_normal;
    d.normals.insert(d.normals.end(), {static_cast<float>(n.x()), static_cast<float>(n.y()),
                                       static_cast<float>(n.z())});
    Eigen::Vector3d t = c.frame.col(0) - n * n.dot(c.frame.col(0));
    t = t.norm() > 1e-9 ? t.normalized() : n.unitOrthogonal();
    const float w = n.cross(t).dot(c.frame.col(1)) >= 0.0 ? 1.0f : -1.0f;
    d.tangents.insert(d.tangents.end(), {static_cast<float>(t.x()), static_cast<float>(t.y()),
                                         static_cast<float>(t.z()), w});
    d.texcoords.insert(d.texcoords.end(), {c.uv_down.x(), c.uv_down.y()});
  });
  return primitives;
}

// The glTF document and its binary chunk, filled a primitive at a time.
class GlbBuilder {
 public:
  GlbBuilder() {
    gltf_["asset"] = {{"version", "2.0"}, {"generator", "texlume"}};
    gltf_["scene"] = 0;
    gltf_["scenes"] = {{{"nodes", {0}}}};
    gltf_["samplers"] = {
        {{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 33071}, {"wrapT", 33071}}};
    for (const char* key : {"accessors", "bufferViews", "images", "textures", "materials"})
      gltf_[key] = nlohmann::json::array();
  }

  void SetNode(const Eigen::Matrix4d& gltf_from_model) {
    gltf_["nodes"] = {
        {{"mesh", 0},
         {"name", "model"},
         {"matrix", ColumnMajor(gltf_from_model)},
         {"extras",
          {{"texlume_frame",
            {{"gltf_from_colmap", ColumnMajor(gltf_from_model)},
             {"colmap_from_gltf", ColumnMajor(gltf_from_model.inverse())},
             {"meaning",
              "the mesh's coordinates are the COLMAP model's; the node's matrix "
              "(gltf_from_colmap, column-major) stands it in glTF's frame: +Y up as the "
              "photos were taken, +Z toward the photos' side, its lowest point at Y = 0"}}}}}}};
  }

  void AddPrimitive(const PrimitiveData& d, const GlbAtlas& atlas, int index) {
    const std::size_t count = d.NumCorners();
    const int first = static_cast<int>(gltf_["accessors"].size());
    Accessor(AddView(d.positions.data(), d.positions.size() * 4, kArrayBuffer), count, "VEC3",
             kFloat);
    gltf_["accessors"].back()["min"] = {d.lo.x(), d.lo.y(), d.lo.z()};
    gltf_["accessors"].back()["max"] = {d.hi.x(), d.hi.y(), d.hi.z()};
    Accessor(AddView(d.normals.data(), d.normals.size() * 4, kArrayBuffer), count, "VEC3", kFloat);
    Accessor(AddView(d.tangents.data(), d.tangents.size() * 4, kArrayBuffer), count, "VEC4",
             kFloat);
    Accessor(AddView(d.texcoords.data(), d.texcoords.size() * 4, kArrayBuffer), count, "VEC2",
             kFloat);
    std::vector<std::uint32_t> indices(count);
    for (std::size_t i = 0; i < count; ++i) indices[i] = static_cast<std::uint32_t>(i);
    Accessor(AddView(indices.data(), indices.size() * 4, kElementArrayBuffer), count, "SCALAR",
             kUnsignedInt);
    primitives_.push_back({{"attributes",
                            {{"POSITION", first},
                             {"NORMAL", first + 1},
                             {"TANGENT", first + 2},
                             {"TEXCOORD_0", first + 3}}},
                           {"indices", first + 4},
                           {"material", AddMaterial(atlas, index)},
                           {"mode", kTriangles}});
  }

  // The GLB container (glTF 2.0 §4.4): header, JSON chunk, BIN chunk.
  void Write(const fs::path& path) {
    while (bin_.size() % 4) bin_.push_back(0);  // the BIN chunk's length is a multiple of 4
    gltf_["meshes"] = {{{"primitives", primitives_}, {"name", "model"}}};
    gltf_["buffers"] = {{{"byteLength", bin_.size()}}};
    gltf_["extensionsUsed"] = {kGltfPtmExtension};
    std::string json = gltf_.dump();
    while (json.size() % 4) json.push_back(' ');
    const std::uint64_t total = 12 + 8 + json.size() + 8 + bin_.size();
    if (total > std::numeric_limits<std::uint32_t>::max())
      throw std::runtime_error(path.string() + ": the model needs " + std::to_string(total) +
                               " bytes, more than the 4 GiB a GLB can hold");
    WriteFileAtomically(
        path,
        [&](std::ostream& out) {
          WriteU32(out, 0x46546C67);  // "glTF"
          WriteU32(out, 2);
          WriteU32(out, static_cast<std::uint32_t>(total));
          WriteU32(out, static_cast<std::uint32_t>(json.size()));
          WriteU32(out, 0x4E4F534A);  // "JSON"
          out.write(json.data(), static_cast<std::streamsize>(json.size()));
          WriteU32(out, static_cast<std::uint32_t>(bin_.size()));
          WriteU32(out, 0x004E4942);  // "BIN\0"
          out.write(reinterpret_cast<const char*>(bin_.data()),
                    static_cast<std::streamsize>(bin_.size()));
        },
        true);
  }

 private:
  int AddView(const void* data, std::size_t bytes, int target) {
    while (bin_.size() % 4) bin_.push_back(0);
    nlohmann::json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes}};
    if (target) view["target"] = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bin_.insert(bin_.end(), p, p + bytes);
    gltf_["bufferViews"].push_back(view);
    return static_cast<int>(gltf_["bufferViews"].size() - 1);
  }

  void Accessor(int view, std::size_t count, const char* type, int component_type) {
    gltf_["accessors"].push_back({{"bufferView", view},
                                  {"componentType", component_type},
                                  {"count", count},
                                  {"type", type}});
  }

  int AddTexture(const std::vector<unsigned char>& png, const std::string& name) {
    gltf_["images"].push_back({{"bufferView", AddView(png.data(), png.size(), 0)},
                               {"mimeType", "image/png"},
                               {"name", name}});
    gltf_["textures"].push_back({{"source", gltf_["images"].size() - 1}, {"sampler", 0}});
    return static_cast<int>(gltf_["textures"].size() - 1);
  }

  int AddMaterial(const GlbAtlas& atlas, int index) {
    const std::string k = std::to_string(index);
    const int albedo = AddTexture(atlas.albedo_png, "albedo_" + k);
    const int normal = AddTexture(atlas.normal_png, "normal_" + k);
    nlohmann::json ptm = atlas.ptm_fields;
    ptm["planes"] = nlohmann::json::array();
    for (std::size_t j = 0; j < atlas.ptm_plane_pngs.size(); ++j) {
      const int plane =
          AddTexture(atlas.ptm_plane_pngs[j], "ptm_" + k + "_plane_" + std::to_string(j));
      ptm["planes"].push_back({{"index", plane}, {"texCoord", 0}});
    }
    if (!atlas.horizon_pngs.empty()) {
      ptm["horizon"] = atlas.horizon_fields;
      ptm["horizon"]["textures"] = nlohmann::json::array();
      for (std::size_t j = 0; j < atlas.horizon_pngs.size(); ++j) {
        const int texture =
            AddTexture(atlas.horizon_pngs[j], "horizon_" + k + "_" + std::to_string(j));
        ptm["horizon"]["textures"].push_back({{"index", texture}, {"texCoord", 0}});
      }
    }
    gltf_["materials"].push_back({{"name", "atlas_" + k},
                                  {"pbrMetallicRoughness",
                                   {{"baseColorTexture", {{"index", albedo}}},
                                    {"metallicFactor", 0.0},
                                    {"roughnessFactor", 1.0}}},
                                  {"normalTexture", {{"index", normal}}},
                                  {"extensions", {{kGltfPtmExtension, ptm}}},
                                  {"extras", atlas.extras}});
    return static_cast<int>(gltf_["materials"].size() - 1);
  }

  nlohmann::json gltf_;
  nlohmann::json primitives_ = nlohmann::json::array();
  std::vector<unsigned char> bin_;
};

}  // namespace

Eigen::Matrix4d GltfFromModel(const TexturedModel& model) {
  // glTF's x, y (up), z (front) are the hemisphere frame's y, z, x.
  const Eigen::Matrix3d hemisphere = model.orientation.HemisphereFromWorld();
  Eigen::Matrix3d rotation;
  rotation << hemisphere.row(1), hemisphere.row(2), hemisphere.row(0);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (const Eigen::Vector3d& v : model.mesh.vertices) {
    lo = lo.cwiseMin(rotation * v);
    hi = hi.cwiseMax(rotation * v);
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation;
  if (!model.mesh.vertices.empty())
    m.topRightCorner<3, 1>() =
        -Eigen::Vector3d(0.5 * (lo.x() + hi.x()), lo.y(), 0.5 * (lo.z() + hi.z()));
  return m;
}

void WriteGlb(const fs::path& path, const TexturedModel& model,
              const std::vector<GlbAtlas>& atlases) {
  TEXLUME_CHECK(atlases.size() == model.atlases.size(), "one GLB entry per atlas");
  GlbBuilder glb;
  glb.SetNode(GltfFromModel(model));
  const std::vector<PrimitiveData> primitives = PrimitivesByAtlas(model);
  for (std::size_t a = 0; a < primitives.size(); ++a)
    if (primitives[a].NumCorners() > 0)
      glb.AddPrimitive(primitives[a], atlases[a], static_cast<int>(a));
  glb.Write(path);
}

}  // namespace texlume::model
