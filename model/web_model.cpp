#include "model/web_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <unordered_map>

#include "core/check.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "synth/mesh_synthesis.h"

namespace texlume::model {
namespace fs = std::filesystem;
namespace {

int Find(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

std::vector<unsigned char> ReadBytes(const fs::path& path) {
  std::ifstream in = OpenForReading(path, true);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
}

// The web model's channels of a PTM (docs/viewer.md, "Web model"): LRGB, a0..a5
// of the luminance times s, then r / s and g / s; RGB, coefficient k of channel c
// at 3 k + c.
std::vector<std::vector<float>> WebChannels(const ptm::Ptm& ptm) {
  const std::size_t texels = ptm.NumTexels();
  const bool lrgb = ptm.format == ptm::PtmFormat::kLrgb;
  std::vector<std::vector<float>> channels(lrgb ? 8 : 18, std::vector<float>(texels));
  for (std::size_t t = 0; t < texels; ++t) {
    if (lrgb) {
      // L (r, g, b) = (L s) (r, g, b) / s with s = (r + g + b) / 3 (eq. 2).
      const float* colour = &ptm.colour[t * 3];
      const float s = (colour[0] + colour[1] + colour[2]) / 3.0f;
      for (int i = 0; i < 6; ++i)
        channels[static_cast<std::size_t>(i)][t] = ptm.Coefficients(t)[i] * s;
      channels[6][t] = s > 1e-6f ? colour[0] / s : 1.0f;  // black: any colour
      channels[7][t] = s > 1e-6f ? colour[1] / s : 1.0f;
    } else {
      for (int i = 0; i < 6; ++i)
        for (int c = 0; c < 3; ++c)
          channels[static_cast<std::size_t>(3 * i + c)][t] = ptm.Coefficients(t, c)[i];
    }
  }
  return channels;
}

}  // namespace

std::vector<int> ChartsOfModel(const TexturedModel& model) {
  const std::size_t num_faces = model.mesh.faces.size();
  std::vector<int> parent(num_faces);
  std::iota(parent.begin(), parent.end(), 0);
  // Edge (lower vertex, higher vertex) -> (face, corner of the lower vertex).
  std::unordered_map<std::uint64_t, std::pair<int, int>> first_side;
  auto uv_of = [&](std::size_t f, int vertex) {
    for (int k = 0; k < 3; ++k)
      if (model.mesh.faces[f][static_cast<std::size_t>(k)] == vertex)
        return model.corner_px[f][static_cast<std::size_t>(k)];
    return Eigen::Vector2f(Eigen::Vector2f::Constant(-1e9f));
  };
  for (std::size_t f = 0; f < num_faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = model.mesh.faces[f][static_cast<std::size_t>(k)];
      const int b = model.mesh.faces[f][static_cast<std::size_t>((k + 1) % 3)];
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                                static_cast<std::uint32_t>(std::max(a, b));
      const auto [it, inserted] = first_side.emplace(key, std::make_pair(static_cast<int>(f), a));
      if (inserted) continue;
      const auto g = static_cast<std::size_t>(it->second.first);
      if (model.face_atlas[g] != model.face_atlas[f]) continue;
      if ((uv_of(f, a) - uv_of(g, a)).norm() > 1e-3f || (uv_of(f, b) - uv_of(g, b)).norm() > 1e-3f)
        continue;
      parent[static_cast<std::size_t>(Find(parent, static_cast<int>(f)))] =
          Find(parent, static_cast<int>(g));
    }
  }
  std::vector<int> chart(num_faces, -1);
  std::unordered_map<int, int> id_of_root;
  for (std::size_t f = 0; f < num_faces; ++f) {
    const int root = Find(parent, static_cast<int>(f));
    const auto [it, inserted] = id_of_root.emplace(root, static_cast<int>(id_of_root.size()));
    chart[f] = it->second;
  }
  return chart;
}

std::vector<cv::Mat> AtlasChartRegions(const TexturedModel& model) {
  const std::vector<int> chart = ChartsOfModel(model);
  TEXLUME_CHECK(model.corner_px.size() == model.mesh.faces.size() &&
                    model.face_atlas.size() == model.mesh.faces.size(),
                "texture coordinates and an atlas per face");
  std::vector<cv::Mat> regions;
  for (const ptm::Ptm& a : model.atlases) regions.emplace_back(a.height, a.width, CV_32SC1, -1);
  constexpr int kShift = 4;  // sub-texel corners
  for (std::size_t f = 0; f < model.corner_px.size(); ++f) {
    if (model.face_atlas[f] < 0) continue;
    const auto a = static_cast<std::size_t>(model.face_atlas[f]);
    if (a >= regions.size()) continue;
    cv::Point corners[3];
    for (std::size_t k = 0; k < 3; ++k)  // texel centres at +0.5
      corners[k] = cv::Point(
          static_cast<int>(std::lround((model.corner_px[f][k].x() - 0.5f) * (1 << kShift))),
          static_cast<int>(std::lround((model.corner_px[f][k].y() - 0.5f) * (1 << kShift))));
    cv::fillConvexPoly(regions[a], corners, 3, cv::Scalar(chart[f]), cv::LINE_8, kShift);
  }
  return regions;
}

namespace {

// The web model's horizon files of atlas `k`, added to `web`; its scene entry.
nlohmann::json HorizonFiles(const ptm::SelfShadowing& shadowing, const std::string& k,
                            WebModel& web) {
  HorizonTextures textures = EncodeHorizonTextures(shadowing, "the horizon of atlas " + k);
  nlohmann::json files = nlohmann::json::array();
  for (std::size_t i = 0; i < textures.pngs.size(); ++i) {
    const std::string name = "horizon_" + k + "_" + std::to_string(i) + ".png";
    web.files[name] = std::move(textures.pngs[i]);
    files.push_back(name);
  }
  textures.fields["files"] = files;
  return textures.fields;
}

}  // namespace

WebModel BuildWebModel(const fs::path& model_dir) {
  const TexturedModel model = ReadModelFolder(model_dir);
  const nlohmann::json manifest = ReadModelManifest(model_dir);
  WebModel web;
  nlohmann::json& scene = web.scene;
  scene["format"] = "texlume-web-3";
  scene["faces"] = model.mesh.faces.size();
  scene["horizon_elevation_deg"] = ptm::kHorizonElevationDeg;
  scene["light_response"] = LightResponseJson(model.light_response);
  const std::vector<int> chart = ChartsOfModel(model);
  scene["charts"] = chart.empty() ? 0 : *std::max_element(chart.begin(), chart.end()) + 1;

  // Geometry: per face corner, faces grouped by atlas.
  const std::size_t n = model.mesh.faces.size() * 3;
  std::vector<float> position, normal, face_normal, tangent, uv, face_id, chart_id;
  position.reserve(n * 3);
  normal.reserve(n * 3);
  face_normal.reserve(n * 3);
  tangent.reserve(n * 3);
  uv.reserve(n * 2);
  face_id.reserve(n);
  chart_id.reserve(n);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (const Eigen::Vector3d& v : model.mesh.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  nlohmann::json ranges = nlohmann::json::array();
  std::size_t corners = 0;
  ForEachCornerByAtlas(model, [&](const ModelCorner& c) {
    if (ranges.empty() || ranges.back()["atlas"].get<int>() != c.atlas)
      ranges.push_back({{"atlas", c.atlas}, {"first_vertex", corners}, {"vertices", 0}});
    ranges.back()["vertices"] = ranges.back()["vertices"].get<std::size_t>() + 1;
    ++corners;
    for (int d = 0; d < 3; ++d) {
      position.push_back(static_cast<float>(c.position[d]));
      normal.push_back(static_cast<float>(c.smooth_normal[d]));
      face_normal.push_back(static_cast<float>(c.frame(d, 2)));
      tangent.push_back(static_cast<float>(c.frame(d, 0)));
    }
    // Texture coordinates in [0, 1], v up (the image's first row at v = 1).
    uv.push_back(c.uv_down.x());
    uv.push_back(1.0f - c.uv_down.y());
    face_id.push_back(static_cast<float>(c.face));
    chart_id.push_back(static_cast<float>(chart[c.face]));
  });
  std::vector<unsigned char> geometry;
  nlohmann::json attributes;
  auto append = [&](const char* name, const std::vector<float>& values, int components) {
    attributes[name] = {{"byte_offset", geometry.size()}, {"components", components}};
    const std::size_t at = geometry.size();
    geometry.resize(at + values.size() * sizeof(float));
    std::memcpy(geometry.data() + at, values.data(), values.size() * sizeof(float));
  };
  append("position", position, 3);
  append("normal", normal, 3);
  append("face_normal", face_normal, 3);
  append("tangent", tangent, 3);
  append("uv", uv, 2);
  append("face", face_id, 1);
  append("chart", chart_id, 1);
  scene["geometry"] = {{"file", "geometry.bin"},
                       {"type", "float32 little-endian, one attribute after another"},
                       {"vertices", n},
                       {"attributes", attributes},
                       {"ranges", ranges}};
  scene["bounds"] = {{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}};
  web.files["geometry.bin"] = std::move(geometry);

  // Atlases: the PTM's values as 8-bit channels with a scale and bias each,
  // four per RGBA PNG (docs/viewer.md, "Web model"):
  //   LRGB: a0..a5 of the luminance, then the colour's r and g, with the colour
  //         rescaled to sum to 3 (b = 3 - r - g) and the luminance by the inverse;
  //   RGB:  coefficient k of channel c at 3 k + c.
  scene["atlases"] = nlohmann::json::array();
  const nlohmann::json& entries = manifest["atlases"];
  const nlohmann::json baked = manifest.contains("baselines") && manifest["baselines"].is_object()
                                   ? manifest["baselines"].value("baked", nlohmann::json::array())
                                   : nlohmann::json::array();
  for (std::size_t a = 0; a < model.atlases.size(); ++a) {
    const ptm::Ptm& ptm = model.atlases[a];
    const std::string k = std::to_string(a);
    const bool lrgb = ptm.format == ptm::PtmFormat::kLrgb;
    nlohmann::json entry = {
        {"width", ptm.width}, {"height", ptm.height}, {"format", lrgb ? "LRGB" : "RGB"}};
    const std::vector<std::vector<float>> channels = WebChannels(ptm);
    const std::size_t num_channels = channels.size();
    std::vector<QuantisedPlane> quantised(num_channels);
    for (std::size_t c = 0; c < num_channels; ++c) quantised[c] = QuantisePlane(channels[c]);
    nlohmann::json textures = nlohmann::json::array();
    for (std::size_t first = 0; first < num_channels; first += 4) {
      std::vector<const QuantisedPlane*> rgba;
      nlohmann::json scale = nlohmann::json::array(), bias = nlohmann::json::array();
      for (std::size_t c = first; c < std::min(first + 4, num_channels); ++c) {
        rgba.push_back(&quantised[c]);
        scale.push_back(quantised[c].scale);
        bias.push_back(quantised[c].bias);
      }
      const std::string name = "ptm_" + k + "_" + std::to_string(first / 4) + ".png";
      web.files[name] = PlanesPng(rgba, ptm.width, ptm.height, name);
      textures.push_back({{"file", name}, {"scale", scale}, {"bias", bias}});
    }
    entry["textures"] = textures;
    if (!model.shadowing.empty()) entry["horizon"] = HorizonFiles(model.shadowing[a], k, web);
    if (a < entries.size() && entries[a].is_object() && entries[a].contains("base_colour")) {
      const std::string name =
          ManifestFileName(entries[a]["base_colour"], model_dir, "base_colour");
      web.files[name] = ReadBytes(model_dir / name);
      entry["base_colour"] = name;
    }
    if (a < baked.size() && baked[a].is_string()) {
      const std::string name = ManifestFileName(baked[a], model_dir, "baked");
      if (fs::exists(model_dir / name)) {
        web.files[name] = ReadBytes(model_dir / name);
        entry["baked"] = name;
      }
    }
    scene["atlases"].push_back(entry);
  }
  if (manifest.contains("baselines") && manifest["baselines"].is_object() &&
      manifest["baselines"].contains("flat_albedo"))
    scene["flat_albedo"] = manifest["baselines"]["flat_albedo"];
  else
    scene["flat_albedo"] = {0.5, 0.5, 0.5};
  const std::string text = scene.dump(1);
  web.files["scene.json"] = std::vector<unsigned char>(text.begin(), text.end());
  return web;
}

}  // namespace texlume::model
