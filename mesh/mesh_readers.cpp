#include "mesh/mesh_readers.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/memory_budget.h"

namespace texlume::mesh {
namespace {

// Lines of a text file with their 1-based numbers; '\r' before '\n' is dropped.
class LineCursor {
 public:
  explicit LineCursor(std::string_view bytes) : bytes_(bytes) {}
  bool Next(std::string_view& line) {
    if (pos_ >= bytes_.size()) return false;
    const std::size_t end = std::min(bytes_.find('\n', pos_), bytes_.size());
    line = bytes_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  std::size_t number() const { return number_; }
  std::size_t offset() const { return std::min(pos_, bytes_.size()); }
  std::size_t remaining() const { return bytes_.size() - offset(); }

 private:
  std::string_view bytes_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

// Refuses a count the limits or the bytes left cannot hold (each item takes at
// least `min_item_bytes`).
void CheckAnnouncedCount(std::uint64_t count, std::uint64_t limit, std::uint64_t min_item_bytes,
                         std::uint64_t bytes_left, const std::string& what,
                         const std::string& label, std::size_t line) {
  if (count > limit) {
    throw InputError(label,
                     "announces " + std::to_string(count) + " " + what +
                         ", more than texlume's limit of " + std::to_string(limit),
                     line);
  }
  if (min_item_bytes > 0 && count > bytes_left / min_item_bytes) {
    throw InputError(label,
                     "announces " + std::to_string(count) + " " + what + " but the " +
                         std::to_string(bytes_left) + " bytes that follow hold at most " +
                         std::to_string(bytes_left / min_item_bytes),
                     line);
  }
}

// A vertex index read from a file, as an int (the soup's index type).
int IndexFromFile(std::int64_t index, std::size_t face, const std::string& label,
                  std::size_t line) {
  if (index < 0 || index > INT_MAX) {
    throw InputError(label,
                     "face " + std::to_string(face) + " has vertex index " + std::to_string(index) +
                         ", which is not a valid index",
                     line);
  }
  return static_cast<int>(index);
}

// ---------------------------------------------------------------- PLY

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> PlyTypeNamed(std::string_view name) {
  static const std::map<std::string_view, PlyType> kTypes = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  const auto it = kTypes.find(name);
  if (it == kTypes.end()) return std::nullopt;
  return it->second;
}

std::size_t PlyTypeBytes(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 8;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::size_t line = 0;
  std::vector<PlyProperty> properties;
  // Per property what its values are for: a coordinate (0..2), the face's corners
  // (3), or nothing (-1); set once the header is read.
  std::vector<int> roles;
  // The fewest bytes one instance takes (binary) or its fewest tokens (ascii).
  std::uint64_t MinBinaryBytes() const {
    std::uint64_t n = 0;
    for (const auto& p : properties) n += PlyTypeBytes(p.is_list ? p.count_type : p.type);
    return n;
  }
};

enum class PlyFormat { kAscii, kBinaryLittle, kBinaryBig };

// Reads a PLY file: a strict header check first (every element and property
// well formed, the counts plausible for the bytes that follow), then the body.
class PlyParser {
 public:
  PlyParser(std::string_view bytes, const std::string& label) : bytes_(bytes), label_(label) {}

  PolygonSoup Run() {
    ParseHeader();
    CheckElements();
    if (format_ == PlyFormat::kAscii) {
      ReadAsciiBody();
    } else {
      ReadBinaryBody();
    }
    return std::move(soup_);
  }

 private:
  void ParseHeader() {
    LineCursor lines(bytes_);
    std::string_view line;
    if (!lines.Next(line) || line != "ply") {
      throw InputError(label_, "not a PLY file (the first line is not 'ply')", 1);
    }
    while (true) {
      if (lines.offset() > MeshReadLimits::kMaxPlyHeaderBytes) {
        throw InputError(label_, "the PLY header has no 'end_header' in its first " +
                                     std::to_string(MeshReadLimits::kMaxPlyHeaderBytes) + " bytes");
      }
      if (!lines.Next(line)) throw InputError(label_, "the PLY header ends without 'end_header'");
      const std::vector<std::string_view> tokens = SplitWhitespace(line);
      if (tokens.empty()) continue;
      if (tokens[0] == "end_header") break;
      HeaderLine(tokens, lines.number());
    }
    body_offset_ = lines.offset();
    if (!format_known_) throw InputError(label_, "the PLY header has no 'format' line");
  }

  void HeaderLine(const std::vector<std::string_view>& tokens, std::size_t line) {
    if (tokens[0] == "comment" || tokens[0] == "obj_info") return;
    if (tokens[0] == "format") return FormatLine(tokens, line);
    if (tokens[0] == "element") return ElementLine(tokens, line);
    if (tokens[0] == "property") return PropertyLine(tokens, line);
    throw InputError(label_, "unknown PLY header keyword '" + std::string(tokens[0]) + "'", line);
  }

  void FormatLine(const std::vector<std::string_view>& tokens, std::size_t line) {
    if (tokens.size() != 3 || tokens[2] != "1.0") {
      throw InputError(
          label_, "expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'", line);
    }
    if (tokens[1] == "ascii") {
      format_ = PlyFormat::kAscii;
    } else if (tokens[1] == "binary_little_endian") {
      format_ = PlyFormat::kBinaryLittle;
    } else if (tokens[1] == "binary_big_endian") {
      format_ = PlyFormat::kBinaryBig;
    } else {
      throw InputError(label_, "unknown PLY format '" + std::string(tokens[1]) + "'", line);
    }
    format_known_ = true;
  }

  void ElementLine(const std::vector<std::string_view>& tokens, std::size_t line) {
    if (tokens.size() != 3) throw InputError(label_, "expected 'element <name> <count>'", line);
    PlyElement element;
    element.name = std::string(tokens[1]);
    element.count = ParseUnsigned(tokens[2], "the element count", label_, line);
    element.line = line;
    elements_.push_back(std::move(element));
  }

  void PropertyLine(const std::vector<std::string_view>& tokens, std::size_t line) {
    if (elements_.empty()) throw InputError(label_, "a 'property' line before any 'element'", line);
    PlyProperty property;
    const bool is_list = tokens.size() >= 2 && tokens[1] == "list";
    if (is_list ? tokens.size() != 5 : tokens.size() != 3) {
      throw InputError(
          label_, "expected 'property <type> <name>' or 'property list <count type> <type> <name>'",
          line);
    }
    property.is_list = is_list;
    property.type = TypeNamed(tokens[is_list ? 3 : 1], line);
    if (is_list) {
      property.count_type = TypeNamed(tokens[2], line);
      if (property.count_type == PlyType::kFloat32 || property.count_type == PlyType::kFloat64) {
        throw InputError(label_, "a list's count type must be an integer type", line);
      }
    }
    property.name = std::string(tokens.back());
    elements_.back().properties.push_back(std::move(property));
  }

  PlyType TypeNamed(std::string_view name, std::size_t line) const {
    const auto type = PlyTypeNamed(name);
    if (!type) throw InputError(label_, "unknown PLY type '" + std::string(name) + "'", line);
    return *type;
  }

  // Every element has properties; the vertex element has x, y, z scalars; the
  // face element a vertex index list; counts fit the bytes after the header.
  void CheckElements() {
    const std::uint64_t body_bytes = bytes_.size() - body_offset_;
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      const PlyElement& element = elements_[e];
      if (element.properties.empty() && element.count > 0) {
        throw InputError(label_, "element '" + element.name + "' has no properties", element.line);
      }
      // An ascii instance takes at least two bytes (a digit and a separator) per value.
      const std::uint64_t min_bytes =
          format_ == PlyFormat::kAscii ? 2 * element.properties.size() : element.MinBinaryBytes();
      const std::uint64_t limit =
          element.name == "face" ? MeshReadLimits::kMaxFaces : MeshReadLimits::kMaxVertices;
      CheckAnnouncedCount(element.count, limit, min_bytes, body_bytes,
                          "'" + element.name + "' elements", label_, element.line);
      if (element.name == "vertex") vertex_element_ = e;
      if (element.name == "face") face_element_ = e;
    }
    if (!vertex_element_) throw InputError(label_, "the PLY header has no 'vertex' element");
    for (const char* axis : {"x", "y", "z"}) {
      if (PropertyIndex(*vertex_element_, axis, false) < 0) {
        throw InputError(label_,
                         std::string("the 'vertex' element has no scalar property '") + axis + "'");
      }
    }
    if (face_element_ && FaceListIndex() < 0) {
      throw InputError(label_, "the 'face' element has no 'vertex_indices' list");
    }
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      for (std::size_t p = 0; p < elements_[e].properties.size(); ++p) {
        elements_[e].roles.push_back(RoleOf(e, p));
      }
    }
  }

  int PropertyIndex(std::size_t element, std::string_view name, bool is_list) const {
    const auto& properties = elements_[element].properties;
    for (std::size_t p = 0; p < properties.size(); ++p) {
      if (properties[p].name == name && properties[p].is_list == is_list)
        return static_cast<int>(p);
    }
    return -1;
  }
  int FaceListIndex() const {
    const int p = PropertyIndex(*face_element_, "vertex_indices", true);
    return p >= 0 ? p : PropertyIndex(*face_element_, "vertex_index", true);
  }

  // What one property's values are for: a coordinate (0..2), the face's
  // corners (3), or nothing (-1).
  int RoleOf(std::size_t element, std::size_t property) const {
    if (vertex_element_ && element == *vertex_element_ &&
        !elements_[element].properties[property].is_list) {
      const std::string& name = elements_[element].properties[property].name;
      if (name == "x") return 0;
      if (name == "y") return 1;
      if (name == "z") return 2;
    }
    if (face_element_ && element == *face_element_ &&
        static_cast<int>(property) == FaceListIndex()) {
      return 3;
    }
    return -1;
  }

  void BeginElement(std::size_t element) {
    if (vertex_element_ && element == *vertex_element_) {
      soup_.vertices.reserve(elements_[element].count);
    }
    if (face_element_ && element == *face_element_)
      soup_.polygons.reserve(elements_[element].count);
  }

  // ---- ascii body: whitespace separated tokens, lines counted for errors.
  void ReadAsciiBody() {
    ascii_pos_ = body_offset_;
    ascii_line_ = 1 + static_cast<std::size_t>(
                          std::count(bytes_.begin(), bytes_.begin() + body_offset_, '\n'));
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      BeginElement(e);
      for (std::uint64_t i = 0; i < elements_[e].count; ++i) ReadAsciiInstance(e);
    }
  }

  void ReadAsciiInstance(std::size_t e) {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    const auto& properties = elements_[e].properties;
    for (std::size_t p = 0; p < properties.size(); ++p) {
      const int role = elements_[e].roles[p];
      if (!properties[p].is_list) {
        const std::string_view token = NextToken();
        if (role >= 0 && role < 3) {
          position[role] = ParseDouble(token, "a coordinate", label_, ascii_line_);
        } else {
          AnyNumber(token);  // a normal or a colour may be nan: texlume does not read it
        }
        continue;
      }
      const std::uint64_t n = ParseUnsigned(NextToken(), "a PLY list count", label_, ascii_line_);
      CheckAnnouncedCount(n, role == 3 ? MeshReadLimits::kMaxCornersPerFace : ~std::uint64_t{0}, 2,
                          bytes_.size() - ascii_pos_, "list items", label_, ascii_line_);
      std::vector<int> polygon;
      if (role == 3) polygon.reserve(n);
      for (std::uint64_t k = 0; k < n; ++k) {
        const std::string_view token = NextToken();
        if (role == 3) {
          polygon.push_back(IndexFromFile(ParseSigned(token, "a vertex index", label_, ascii_line_),
                                          soup_.polygons.size(), label_, ascii_line_));
        } else {
          AnyNumber(token);
        }
      }
      if (role == 3) soup_.polygons.push_back(std::move(polygon));
    }
    if (vertex_element_ && e == *vertex_element_) soup_.vertices.push_back(position);
  }

  // A value texlume skips: any number, nan and inf included.
  void AnyNumber(std::string_view token) const {
    double v = 0;
    const char* begin = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const auto [ptr, ec] = std::from_chars(begin, token.data() + token.size(), v);
    if (ptr != token.data() + token.size() ||
        (ec != std::errc() && ec != std::errc::result_out_of_range)) {
      throw InputError(label_, "expected a number, got '" + std::string(token) + "'", ascii_line_);
    }
  }

  std::string_view NextToken() {
    while (ascii_pos_ < bytes_.size() &&
           std::isspace(static_cast<unsigned char>(bytes_[ascii_pos_]))) {
      if (bytes_[ascii_pos_] == '\n') ++ascii_line_;
      ++ascii_pos_;
    }
    if (ascii_pos_ >= bytes_.size()) {
      throw InputError(label_, "the PLY body ends before all announced elements were read",
                       ascii_line_);
    }
    const std::size_t start = ascii_pos_;
    while (ascii_pos_ < bytes_.size() &&
           !std::isspace(static_cast<unsigned char>(bytes_[ascii_pos_]))) {
      ++ascii_pos_;
    }
    return bytes_.substr(start, ascii_pos_ - start);
  }

  // ---- binary body: every read is checked against the bytes left.
  void ReadBinaryBody() {
    binary_pos_ = body_offset_;
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      BeginElement(e);
      for (std::uint64_t i = 0; i < elements_[e].count; ++i) ReadBinaryInstance(e);
    }
  }

  void ReadBinaryInstance(std::size_t e) {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    const auto& properties = elements_[e].properties;
    for (std::size_t p = 0; p < properties.size(); ++p) {
      const int role = elements_[e].roles[p];
      if (!properties[p].is_list) {
        const double v = ReadBinaryValue(properties[p].type);
        if (role >= 0 && role < 3) position[role] = v;
        continue;
      }
      const double count = ReadBinaryValue(properties[p].count_type);
      if (count < 0) throw BodyError("a negative list count");
      const auto n = static_cast<std::uint64_t>(count);
      CheckAnnouncedCount(n, role == 3 ? MeshReadLimits::kMaxCornersPerFace : ~std::uint64_t{0},
                          PlyTypeBytes(properties[p].type), bytes_.size() - binary_pos_,
                          "list items", label_, 0);
      std::vector<int> polygon;
      if (role == 3) polygon.reserve(n);
      for (std::uint64_t k = 0; k < n; ++k) {
        const double v = ReadBinaryValue(properties[p].type);
        if (role != 3) continue;
        if (v != std::floor(v)) throw BodyError("a vertex index that is not an integer");
        polygon.push_back(IndexFromFile(static_cast<std::int64_t>(std::clamp(v, -1.0, 1e12)),
                                        soup_.polygons.size(), label_, 0));
      }
      if (role == 3) soup_.polygons.push_back(std::move(polygon));
    }
    if (vertex_element_ && e == *vertex_element_) soup_.vertices.push_back(position);
  }

  double ReadBinaryValue(PlyType type) {
    const std::size_t n = PlyTypeBytes(type);
    if (bytes_.size() - binary_pos_ < n)
      throw BodyError("the body ends before all announced elements");
    std::array<unsigned char, 8> raw{};
    std::memcpy(raw.data(), bytes_.data() + binary_pos_, n);
    binary_pos_ += n;
    const bool file_little = format_ == PlyFormat::kBinaryLittle;
    if (file_little != (std::endian::native == std::endian::little))
      std::reverse(raw.begin(), raw.begin() + n);
    return Decode(type, raw.data());
  }

  static double Decode(PlyType type, const unsigned char* raw) {
    auto as = [raw](auto value) {
      std::memcpy(&value, raw, sizeof(value));
      return static_cast<double>(value);
    };
    switch (type) {
      case PlyType::kInt8:
        return as(std::int8_t{});
      case PlyType::kUint8:
        return as(std::uint8_t{});
      case PlyType::kInt16:
        return as(std::int16_t{});
      case PlyType::kUint16:
        return as(std::uint16_t{});
      case PlyType::kInt32:
        return as(std::int32_t{});
      case PlyType::kUint32:
        return as(std::uint32_t{});
      case PlyType::kFloat32:
        return as(float{});
      case PlyType::kFloat64:
        return as(double{});
    }
    return 0.0;
  }

  InputError BodyError(const std::string& what) const {
    return InputError(label_, what + " at byte " + std::to_string(binary_pos_));
  }

  std::string_view bytes_;
  const std::string& label_;
  PlyFormat format_ = PlyFormat::kAscii;
  bool format_known_ = false;
  std::vector<PlyElement> elements_;
  std::optional<std::size_t> vertex_element_, face_element_;
  std::size_t body_offset_ = 0;
  std::size_t ascii_pos_ = 0, ascii_line_ = 0, binary_pos_ = 0;
  PolygonSoup soup_;
};

// ---------------------------------------------------------------- OBJ

// An OBJ face corner "v", "v/vt", "v//vn" or "v/vt/vn"; negative v counts back
// from the last vertex read so far.
int ObjCorner(std::string_view token, std::size_t vertices_so_far, std::size_t face,
              const std::string& label, std::size_t line) {
  const std::string_view v = token.substr(0, token.find('/'));
  const std::int64_t index = ParseSigned(v, "a face's vertex index", label, line);
  if (index == 0) throw InputError(label, "face vertex index 0 (OBJ indices start at 1)", line);
  const std::int64_t zero_based =
      index > 0 ? index - 1 : static_cast<std::int64_t>(vertices_so_far) + index;
  return IndexFromFile(zero_based, face, label, line);
}

// ---------------------------------------------------------------- OFF

// The OFF body's next line with something on it, comments ('#' onwards) removed.
bool NextOffLine(LineCursor& lines, std::vector<std::string_view>& tokens) {
  std::string_view line;
  while (lines.Next(line)) {
    line = line.substr(0, line.find('#'));
    tokens = SplitWhitespace(line);
    if (!tokens.empty()) return true;
  }
  return false;
}

bool IsOffKeyword(std::string_view token) {
  static const std::array<std::string_view, 8> kKeywords = {"OFF",   "COFF",   "NOFF",   "CNOFF",
                                                            "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
  return std::find(kKeywords.begin(), kKeywords.end(), token) != kKeywords.end();
}

// ---------------------------------------------------------------- STL

// Corners of an STL are welded by exact position, as STL readers do.
class StlSoupBuilder {
 public:
  explicit StlSoupBuilder(const std::string& label) : label_(label) {}
  void AddTriangle(const std::array<Eigen::Vector3d, 3>& corners) {
    for (const Eigen::Vector3d& p : corners) {
      if (!p.allFinite()) {
        throw InputError(label_, "triangle " + std::to_string(soup_.polygons.size()) +
                                     " has a non-finite corner");
      }
    }
    std::vector<int> polygon;
    for (const Eigen::Vector3d& p : corners) {
      const auto [it, inserted] = index_.emplace(std::array<double, 3>{p.x(), p.y(), p.z()},
                                                 static_cast<int>(soup_.vertices.size()));
      if (inserted) soup_.vertices.push_back(p);
      polygon.push_back(it->second);
    }
    soup_.polygons.push_back(std::move(polygon));
  }
  PolygonSoup Take() { return std::move(soup_); }

 private:
  const std::string& label_;
  PolygonSoup soup_;
  std::map<std::array<double, 3>, int> index_;
};

PolygonSoup ParseBinaryStl(std::string_view bytes, std::uint32_t count, const std::string& label) {
  StlSoupBuilder builder(label);
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* record = bytes.data() + 84 + 50 * static_cast<std::size_t>(t);
    std::array<Eigen::Vector3d, 3> corners;
    for (int k = 0; k < 3; ++k) {
      std::array<float, 3> xyz{};
      std::memcpy(xyz.data(), record + 12 * (k + 1), 12);  // after the 12-byte normal
      corners[static_cast<std::size_t>(k)] = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    }
    builder.AddTriangle(corners);
  }
  return builder.Take();
}

PolygonSoup ParseAsciiStl(std::string_view bytes, const std::string& label) {
  StlSoupBuilder builder(label);
  LineCursor lines(bytes);
  std::string_view line;
  std::vector<Eigen::Vector3d> facet;
  bool in_facet = false;
  while (lines.Next(line)) {
    const std::vector<std::string_view> tokens = SplitWhitespace(line);
    if (tokens.empty()) continue;
    const std::string keyword = LowerCase(tokens[0]);  // STL writers differ in case
    if (keyword == "facet") {
      if (in_facet) throw InputError(label, "'facet' inside a facet", lines.number());
      in_facet = true;
      facet.clear();
    } else if (keyword == "vertex") {
      if (!in_facet || tokens.size() != 4 || facet.size() == 3) {
        throw InputError(label, "expected 'vertex x y z', three per facet", lines.number());
      }
      facet.emplace_back(ParseDouble(tokens[1], "x", label, lines.number()),
                         ParseDouble(tokens[2], "y", label, lines.number()),
                         ParseDouble(tokens[3], "z", label, lines.number()));
    } else if (keyword == "endfacet") {
      if (!in_facet || facet.size() != 3) {
        throw InputError(label, "a facet without three vertices", lines.number());
      }
      builder.AddTriangle({facet[0], facet[1], facet[2]});
      in_facet = false;
    }
  }
  if (in_facet) throw InputError(label, "the file ends inside a facet", lines.number());
  return builder.Take();
}

}  // namespace

PolygonSoup ParsePly(std::string_view bytes, const std::string& label) {
  return PlyParser(bytes, label).Run();
}

PolygonSoup ParseObj(std::string_view bytes, const std::string& label) {
  PolygonSoup soup;
  LineCursor lines(bytes);
  std::string_view line;
  while (lines.Next(line)) {
    const std::vector<std::string_view> tokens = SplitWhitespace(line.substr(0, line.find('#')));
    if (tokens.empty()) continue;
    if (tokens[0] == "v") {
      if (tokens.size() < 4) throw InputError(label, "expected 'v x y z'", lines.number());
      if (soup.vertices.size() >= MeshReadLimits::kMaxVertices) {
        throw InputError(
            label,
            "more vertices than texlume's limit of " + std::to_string(MeshReadLimits::kMaxVertices),
            lines.number());
      }
      soup.vertices.emplace_back(ParseDouble(tokens[1], "x", label, lines.number()),
                                 ParseDouble(tokens[2], "y", label, lines.number()),
                                 ParseDouble(tokens[3], "z", label, lines.number()));
    } else if (tokens[0] == "f") {
      if (soup.polygons.size() >= MeshReadLimits::kMaxFaces) {
        throw InputError(
            label,
            "more faces than texlume's limit of " + std::to_string(MeshReadLimits::kMaxFaces),
            lines.number());
      }
      std::vector<int> polygon;
      polygon.reserve(tokens.size() - 1);
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        polygon.push_back(ObjCorner(tokens[k], soup.vertices.size(), soup.polygons.size(), label,
                                    lines.number()));
      }
      soup.polygons.push_back(std::move(polygon));
    }
    // vt, vn, o, g, s, usemtl, mtllib, l, p and comments carry nothing texlume reads.
  }
  return soup;
}

PolygonSoup ParseOff(std::string_view bytes, const std::string& label) {
  LineCursor lines(bytes);
  std::vector<std::string_view> tokens;
  if (!NextOffLine(lines, tokens) || !IsOffKeyword(tokens[0])) {
    throw InputError(label, "not an OFF file (it does not start with 'OFF')", lines.number());
  }
  if (tokens.size() > 1 && LowerCase(std::string(tokens[1])) == "binary") {
    throw InputError(label, "binary OFF is not supported; write it as text OFF or PLY",
                     lines.number());
  }
  tokens.erase(tokens.begin());  // the counts may follow the keyword on its line
  if (tokens.empty() && !NextOffLine(lines, tokens)) {
    throw InputError(label, "the OFF file ends before its counts", lines.number());
  }
  if (tokens.size() < 2) throw InputError(label, "expected 'vertices faces edges'", lines.number());
  const std::size_t count_line = lines.number();
  const std::uint64_t nv = ParseUnsigned(tokens[0], "the vertex count", label, count_line);
  const std::uint64_t nf = ParseUnsigned(tokens[1], "the face count", label, count_line);
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line at least 2.
  CheckAnnouncedCount(nv, MeshReadLimits::kMaxVertices, 6, lines.remaining(), "vertices", label,
                      count_line);
  CheckAnnouncedCount(nf, MeshReadLimits::kMaxFaces, 2, lines.remaining() - 6 * nv, "faces", label,
                      count_line);
  PolygonSoup soup;
  soup.vertices.reserve(nv);
  soup.polygons.reserve(nf);
  for (std::uint64_t i = 0; i < nv; ++i) {
    if (!NextOffLine(lines, tokens) || tokens.size() < 3) {
      throw InputError(label, "expected vertex " + std::to_string(i) + " as 'x y z'",
                       lines.number());
    }
    soup.vertices.emplace_back(ParseDouble(tokens[0], "x", label, lines.number()),
                               ParseDouble(tokens[1], "y", label, lines.number()),
                               ParseDouble(tokens[2], "z", label, lines.number()));
  }
  for (std::uint64_t f = 0; f < nf; ++f) {
    if (!NextOffLine(lines, tokens)) {
      throw InputError(label, "the file ends before face " + std::to_string(f), lines.number());
    }
    const std::uint64_t n =
        ParseUnsigned(tokens[0], "a face's corner count", label, lines.number());
    if (n > tokens.size() - 1) {
      throw InputError(label,
                       "face " + std::to_string(f) + " announces " + std::to_string(n) +
                           " corners but its line lists fewer",
                       lines.number());
    }
    std::vector<int> polygon;
    polygon.reserve(n);
    for (std::uint64_t k = 1; k <= n; ++k) {
      polygon.push_back(
          IndexFromFile(ParseSigned(tokens[k], "a vertex index", label, lines.number()), f, label,
                        lines.number()));
    }
    soup.polygons.push_back(std::move(polygon));
  }
  return soup;
}

PolygonSoup ParseStl(std::string_view bytes, const std::string& label) {
  // Binary when the count in its header fits its size; ASCII when it starts with
  // "solid"; binary with padding after its triangles otherwise.
  std::uint32_t count = 0;
  if (bytes.size() >= 84) {
    std::memcpy(&count, bytes.data() + 80, 4);
    if constexpr (std::endian::native == std::endian::big) count = __builtin_bswap32(count);
  }
  const std::uint64_t binary_size = 84 + 50 * static_cast<std::uint64_t>(count);
  if (bytes.size() >= 84 && binary_size == bytes.size()) return ParseBinaryStl(bytes, count, label);
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && LowerCase(bytes.substr(first, 5)) == "solid") {
    return ParseAsciiStl(bytes, label);
  }
  if (bytes.size() < 84) throw InputError(label, "too short for an STL file");
  if (binary_size < bytes.size()) return ParseBinaryStl(bytes, count, label);
  throw InputError(label, "binary STL announces " + std::to_string(count) + " triangles (" +
                              std::to_string(binary_size) + " bytes) but the file has " +
                              std::to_string(bytes.size()) + " bytes");
}

PolygonSoup ReadPolygonSoup(const std::filesystem::path& path) {
  const std::string label = path.string();
  const std::string ext = LowerCaseExtension(path);
  using Parser = PolygonSoup (*)(std::string_view, const std::string&);
  Parser parse = nullptr;
  if (ext == ".ply") parse = ParsePly;
  if (ext == ".obj") parse = ParseObj;
  if (ext == ".off") parse = ParseOff;
  if (ext == ".stl") parse = ParseStl;
  if (parse == nullptr) {
    throw InputError(
        label, "unsupported mesh format '" + ext + "' (texlume reads .ply, .obj, .off, .stl)");
  }
  std::error_code ec;
  const auto file_bytes = std::filesystem::file_size(path, ec);
  // The bytes, the soup and the repair's maps: at most about 24 times the file.
  if (!ec)
    RequireMemory(24.0 * static_cast<double>(file_bytes), "reading and repairing the mesh", label);
  const std::string bytes = ReadFileBytes(path, MeshReadLimits::kMaxFileBytes);
  return parse(bytes, label);
}

}  // namespace texlume::mesh
