#include "sfm/lights.h"

#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"

namespace texlume::sfm {
namespace {

Eigen::Vector3d NormalisedDirection(const Eigen::Vector3d& d, const std::string& label,
                                    std::size_t line, const std::string& what) {
  const double n = d.norm();
  if (!(n > 1e-9) || !std::isfinite(n)) {
    throw InputError(label, what + " is zero or not finite", line);
  }
  // Unit vectors as written are kept bit-exact; others are normalised.
  return std::abs(n - 1.0) < 1e-12 ? d : Eigen::Vector3d(d / n);
}

Eigen::Vector3d JsonVector3(const nlohmann::json& j, const std::string& label,
                            const std::string& what) {
  if (!j.is_array() || j.size() != 3) {
    throw InputError(label, what + " must be an array of 3 numbers");
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (!j[static_cast<std::size_t>(i)].is_number()) {
      throw InputError(label, what + " must be an array of 3 numbers");
    }
    v[i] = j[static_cast<std::size_t>(i)].get<double>();
    if (!std::isfinite(v[i])) throw InputError(label, what + " is not finite");
  }
  return v;
}

ObjectLight ParseLight(const nlohmann::json& j, const std::string& label,
                       const std::string& image) {
  const std::string where = "light of image '" + image + "'";
  if (!j.is_object()) throw InputError(label, where + " must be an object");
  ObjectLight light;
  const bool has_direction = j.contains("direction");
  const bool has_position = j.contains("position");
  std::string type = j.value("type", has_position ? "point" : "directional");
  if (type == "directional") {
    if (!has_direction) throw InputError(label, where + ": a directional light needs 'direction'");
    light.kind = ObjectLight::Kind::kDirectional;
    light.direction_in_world = NormalisedDirection(
        JsonVector3(j["direction"], label, where + " 'direction'"), label, 0, where + " direction");
  } else if (type == "point") {
    if (!has_position) throw InputError(label, where + ": a point light needs 'position'");
    light.kind = ObjectLight::Kind::kPoint;
    light.position_in_world = JsonVector3(j["position"], label, where + " 'position'");
  } else {
    throw InputError(label, where + ": unknown type '" + type + "' (directional or point)");
  }
  if (j.contains("intensity")) {
    if (!j["intensity"].is_number() || !(j["intensity"].get<double>() > 0.0) ||
        !std::isfinite(j["intensity"].get<double>())) {
      throw InputError(label, where + ": 'intensity' must be a positive number");
    }
    light.intensity = j["intensity"].get<double>();
  }
  return light;
}

}  // namespace

std::vector<LpEntry> ReadLp(std::istream& in, const std::string& label) {
  std::string line;
  std::size_t line_number = 0;
  std::uint64_t count = 0;
  bool have_count = false;
  while (!have_count && std::getline(in, line)) {
    ++line_number;
    const auto tokens = SplitWhitespace(line);
    if (tokens.empty()) continue;
    if (tokens.size() != 1)
      throw InputError(label, "first line must hold the light count", line_number);
    count = ParseUnsigned(tokens[0], "the light count", label, line_number);
    have_count = true;
  }
  if (!have_count) throw InputError(label, "empty file: expected the light count");
  if (count == 0) throw InputError(label, "light count is 0", line_number);
  std::vector<LpEntry> entries;
  while (entries.size() < count && std::getline(in, line)) {
    ++line_number;
    const auto tokens = SplitWhitespace(line);
    if (tokens.empty()) continue;
    if (tokens.size() < 4) {
      throw InputError(label, "expected 'filename lx ly lz'", line_number);
    }
    const std::size_t n = tokens.size();
    Eigen::Vector3d d(ParseDouble(tokens[n - 3], "lx", label, line_number),
                      ParseDouble(tokens[n - 2], "ly", label, line_number),
                      ParseDouble(tokens[n - 1], "lz", label, line_number));
    LpEntry entry;
    const auto start = static_cast<std::size_t>(tokens[0].data() - line.data());
    const auto end =
        static_cast<std::size_t>(tokens[n - 4].data() - line.data()) + tokens[n - 4].size();
    entry.filename = line.substr(start, end - start);
    entry.direction_in_image = NormalisedDirection(d, label, line_number, "light direction");
    entries.push_back(std::move(entry));
  }
  if (entries.size() < count) {
    throw InputError(label, "the header announces " + std::to_string(count) +
                                " lights but the file lists " + std::to_string(entries.size()));
  }
  while (std::getline(in, line)) {
    ++line_number;
    if (!SplitWhitespace(line).empty()) {
      throw InputError(label,
                       "more light lines than the count " + std::to_string(count) + " announced",
                       line_number);
    }
  }
  std::set<std::string> names;
  for (const auto& e : entries) {
    if (!names.insert(BaseName(e.filename)).second) {
      throw InputError(label, "image '" + e.filename + "' is listed twice");
    }
  }
  return entries;
}

std::vector<LpEntry> ReadLpFile(const std::filesystem::path& path) {
  std::ifstream in = OpenForReading(path, false);
  return ReadLp(in, path.string());
}

void WriteLp(const std::vector<LpEntry>& entries, std::ostream& out) {
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  out << entries.size() << "\n";
  for (const auto& e : entries) {
    out << e.filename << " " << e.direction_in_image.x() << " " << e.direction_in_image.y() << " "
        << e.direction_in_image.z() << "\n";
  }
}

void WriteLpFile(const std::vector<LpEntry>& entries, const std::filesystem::path& path) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { WriteLp(entries, out); }, false);
}

std::string BaseName(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

const LpEntry* FindLpEntry(const std::vector<LpEntry>& entries, const std::string& image_name) {
  const std::string wanted = BaseName(image_name);
  for (const auto& e : entries) {
    if (BaseName(e.filename) == wanted) return &e;
  }
  return nullptr;
}

Eigen::Vector3d ObjectLight::DirectionFrom(const Eigen::Vector3d& point_in_world) const {
  if (kind == Kind::kDirectional) return direction_in_world;
  return (position_in_world - point_in_world).normalized();
}

ObjectLights ReadObjectLights(std::istream& in, const std::string& label) {
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    const std::size_t byte = std::min<std::size_t>(e.byte, text.size());
    const std::size_t line =
        1 + static_cast<std::size_t>(
                std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(byte), '\n'));
    throw InputError(label, std::string("invalid JSON: ") + e.what(), line);
  } catch (const nlohmann::json::exception& e) {  // a number out of range, say
    throw InputError(label, std::string("invalid JSON: ") + e.what());
  }
  if (!root.is_object() || !root.contains("images") || !root["images"].is_object()) {
    throw InputError(label, "expected an object with an 'images' object (see docs/lights.md)");
  }
  if (root.contains("frame") && root["frame"] != "world") {
    throw InputError(label, "only \"frame\": \"world\" is supported");
  }
  ObjectLights lights;
  for (const auto& [name, value] : root["images"].items()) {
    std::vector<ObjectLight> list;
    if (value.is_array()) {
      if (value.empty()) throw InputError(label, "image '" + name + "' has an empty light list");
      for (const auto& j : value) list.push_back(ParseLight(j, label, name));
    } else {
      list.push_back(ParseLight(value, label, name));
    }
    lights[name] = std::move(list);
  }
  return lights;
}

ObjectLights ReadObjectLightsFile(const std::filesystem::path& path) {
  std::ifstream in = OpenForReading(path, false);
  return ReadObjectLights(in, path.string());
}

void WriteObjectLights(const ObjectLights& lights, std::ostream& out) {
  nlohmann::json root;
  root["format"] = "texlume-object-lights";
  root["version"] = 1;
  root["frame"] = "world";
  nlohmann::json images = nlohmann::json::object();
  for (const auto& [name, list] : lights) {
    nlohmann::json arr = nlohmann::json::array();
    for (const auto& l : list) {
      nlohmann::json j;
      if (l.kind == ObjectLight::Kind::kDirectional) {
        j["type"] = "directional";
        j["direction"] = {l.direction_in_world.x(), l.direction_in_world.y(),
                          l.direction_in_world.z()};
      } else {
        j["type"] = "point";
        j["position"] = {l.position_in_world.x(), l.position_in_world.y(), l.position_in_world.z()};
      }
      j["intensity"] = l.intensity;
      arr.push_back(j);
    }
    images[name] = arr;
  }
  root["images"] = images;
  out << root.dump(2) << "\n";
}

void WriteObjectLightsFile(const ObjectLights& lights, const std::filesystem::path& path) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { WriteObjectLights(lights, out); }, false);
}

LightsModelMatch CheckLightsAgainstModel(const ObjectLights& lights,
                                         const Reconstruction& reconstruction,
                                         const std::string& label) {
  std::set<std::string> model_names;
  for (const auto& [id, image] : reconstruction.images) model_names.insert(image.name);
  LightsModelMatch match;
  for (const auto& [name, list] : lights)
    if (!model_names.count(name)) match.lights_without_images.push_back(name);
  if (!lights.empty() && match.lights_without_images.size() == lights.size()) {
    throw InputError(label, "no light entry names an image of the COLMAP model (the first is '" +
                                lights.begin()->first + "')");
  }
  for (const auto& name : model_names)
    if (!lights.count(name)) match.images_without_lights.push_back(name);
  return match;
}

}  // namespace texlume::sfm
