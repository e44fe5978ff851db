#include "sfm/colmap_io.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <tuple>

#include "core/errors.h"
#include "core/file_util.h"

namespace texlume::sfm {
namespace {

constexpr std::uint64_t kInvalidPoint3DIdBinary = std::numeric_limits<std::uint64_t>::max();

// Minimum sizes of binary records, used to bound counts before allocating.
constexpr std::uint64_t kMinCameraBytes = 4 + 4 + 8 + 8;
// Plausibility bounds of a camera's size (docs/robustness.md, "Limits").
constexpr std::uint64_t kMaxCameraSide = 65535;
constexpr std::uint64_t kMaxCameraPixels = 250'000'000;
constexpr std::uint64_t kMinImageBytes = 4 + 4 * 8 + 3 * 8 + 4 + 1 + 8;
constexpr std::uint64_t kPoint2DBytes = 8 + 8 + 8;
constexpr std::uint64_t kMinPoint3DBytes = 8 + 3 * 8 + 3 + 8 + 8;
constexpr std::uint64_t kTrackElementBytes = 4 + 4;

Eigen::Quaterniond QuaternionFromWxyz(double w, double x, double y, double z,
                                      const std::string& label, std::size_t line) {
  Eigen::Quaterniond q(w, x, y, z);
  const double norm = q.norm();
  if (!(norm > 1e-12) || !std::isfinite(norm)) {
    throw InputError(label, "image rotation quaternion has zero or invalid norm", line);
  }
  q.coeffs() /= norm;  // COLMAP normalises on read, too
  return q;
}

// An image name is a path below the images folder: relative, no ".." component.
void CheckImageName(const std::string& name, const std::string& label, std::size_t line) {
  const std::string problem = ContainedNameProblem(name);
  if (!problem.empty()) throw InputError(label, "image name '" + name + "' " + problem, line);
}

Camera MakeCamera(std::uint64_t camera_id, std::int64_t model_id, std::uint64_t width,
                  std::uint64_t height, const std::string& label, std::size_t line) {
  if (camera_id > std::numeric_limits<std::uint32_t>::max() - 1) {
    throw InputError(label, "camera id " + std::to_string(camera_id) + " is out of range", line);
  }
  if (model_id < 0 || model_id >= kNumCameraModels) {
    throw InputError(label,
                     "unknown camera model id " + std::to_string(model_id) +
                         " (COLMAP 3.8 knows 0..10) for camera " + std::to_string(camera_id),
                     line);
  }
  if (width == 0 || height == 0 || width > kMaxCameraSide || height > kMaxCameraSide ||
      width * height > kMaxCameraPixels) {
    throw InputError(label,
                     "camera " + std::to_string(camera_id) + " has an implausible size " +
                         std::to_string(width) + "x" + std::to_string(height) +
                         " (texlume reads photos of at most " + std::to_string(kMaxCameraSide) +
                         " pixels a side and " + std::to_string(kMaxCameraPixels / 1000000) +
                         " megapixels)",
                     line);
  }
  Camera camera;
  camera.camera_id = CameraId(static_cast<std::uint32_t>(camera_id));
  camera.model = static_cast<CameraModelId>(model_id);
  camera.width = width;
  camera.height = height;
  return camera;
}

struct LineReader {
  std::istream& in;
  const std::string& label;
  std::size_t line_number = 0;
  std::string line;

  // Next line that is neither empty nor a comment; false at the end.
  bool NextDataLine() {
    while (std::getline(in, line)) {
      ++line_number;
      const auto tokens = SplitWhitespace(line);
      if (tokens.empty() || tokens[0][0] == '#') continue;
      return true;
    }
    return false;
  }
  // The very next line, whatever it holds; false at the end.
  bool NextRawLine() {
    if (!std::getline(in, line)) return false;
    ++line_number;
    return true;
  }
};

void SetPrecision(std::ostream& out) {
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
}

}  // namespace

std::string ModelFormatName(ModelFormat format) {
  return format == ModelFormat::kText ? "txt" : "bin";
}

// ---------------------------------------------------------------- text readers

std::map<CameraId, Camera> ReadCamerasText(std::istream& in, const std::string& label) {
  std::map<CameraId, Camera> cameras;
  LineReader reader{in, label, 0, {}};
  while (reader.NextDataLine()) {
    const std::size_t ln = reader.line_number;
    const auto tokens = SplitWhitespace(reader.line);
    if (tokens.size() < 4) {
      throw InputError(label, "expected 'CAMERA_ID MODEL WIDTH HEIGHT PARAMS...'", ln);
    }
    const std::uint64_t id = ParseUnsigned(tokens[0], "CAMERA_ID", label, ln);
    const auto model = CameraModelFromName(tokens[1]);
    if (!model) {
      throw InputError(label, "unknown camera model '" + std::string(tokens[1]) + "'", ln);
    }
    Camera camera =
        MakeCamera(id, static_cast<int>(*model), ParseUnsigned(tokens[2], "WIDTH", label, ln),
                   ParseUnsigned(tokens[3], "HEIGHT", label, ln), label, ln);
    const std::size_t expected = static_cast<std::size_t>(CameraModelNumParams(*model));
    if (tokens.size() - 4 != expected) {
      throw InputError(label,
                       std::string(tokens[1]) + " takes " + std::to_string(expected) +
                           " parameters (" + std::string(CameraModelParamsInfo(*model)) +
                           "), found " + std::to_string(tokens.size() - 4),
                       ln);
    }
    for (std::size_t i = 4; i < tokens.size(); ++i) {
      camera.params.push_back(ParseDouble(tokens[i], "a camera parameter", label, ln));
    }
    if (!cameras.emplace(camera.camera_id, camera).second) {
      throw InputError(label, "duplicate camera id " + std::to_string(id), ln);
    }
  }
  return cameras;
}

std::map<ImageId, Image> ReadImagesText(std::istream& in, const std::string& label) {
  std::map<ImageId, Image> images;
  LineReader reader{in, label, 0, {}};
  while (reader.NextDataLine()) {
    const std::size_t ln = reader.line_number;
    const auto tokens = SplitWhitespace(reader.line);
    if (tokens.size() < 10) {
      throw InputError(label, "expected 'IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME'", ln);
    }
    Image image;
    const std::uint64_t id = ParseUnsigned(tokens[0], "IMAGE_ID", label, ln);
    if (id >= std::numeric_limits<std::uint32_t>::max()) {
      throw InputError(label, "image id " + std::to_string(id) + " is out of range", ln);
    }
    image.image_id = ImageId(static_cast<std::uint32_t>(id));
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = ParseDouble(tokens[1 + i], "a pose value", label, ln);
    image.cam_from_world.rotation = QuaternionFromWxyz(v[0], v[1], v[2], v[3], label, ln);
    image.cam_from_world.translation = Eigen::Vector3d(v[4], v[5], v[6]);
    const std::uint64_t camera_id = ParseUnsigned(tokens[8], "CAMERA_ID", label, ln);
    if (camera_id >= std::numeric_limits<std::uint32_t>::max()) {
      throw InputError(label, "camera id " + std::to_string(camera_id) + " is out of range", ln);
    }
    image.camera_id = CameraId(static_cast<std::uint32_t>(camera_id));
    // The name is the rest of the line (COLMAP writes it verbatim).
    const std::size_t name_start = static_cast<std::size_t>(tokens[9].data() - reader.line.data());
    image.name = reader.line.substr(name_start);
    while (!image.name.empty() &&
           (image.name.back() == '\r' || image.name.back() == ' ' || image.name.back() == '\t')) {
      image.name.pop_back();
    }
    CheckImageName(image.name, label, ln);
    // The next line holds the 2D points, possibly none (an empty line).
    if (reader.NextRawLine()) {
      const std::size_t pln = reader.line_number;
      const auto pts = SplitWhitespace(reader.line);
      if (!pts.empty() && pts[0][0] == '#') {
        throw InputError(label, "expected the POINTS2D line of image " + std::to_string(id), pln);
      }
      if (pts.size() % 3 != 0) {
        throw InputError(label,
                         "POINTS2D line of image " + std::to_string(id) +
                             " must hold triples 'X Y POINT3D_ID', found " +
                             std::to_string(pts.size()) + " values",
                         pln);
      }
      image.points2d.reserve(pts.size() / 3);
      for (std::size_t i = 0; i < pts.size(); i += 3) {
        Point2D p;
        p.xy = Eigen::Vector2d(ParseDouble(pts[i], "X", label, pln),
                               ParseDouble(pts[i + 1], "Y", label, pln));
        const std::int64_t point_id = ParseSigned(pts[i + 2], "POINT3D_ID", label, pln);
        if (point_id < -1) throw InputError(label, "negative POINT3D_ID other than -1", pln);
        if (point_id >= 0) p.point3d_id = Point3DId(static_cast<std::uint64_t>(point_id));
        image.points2d.push_back(p);
      }
    }
    if (!images.emplace(image.image_id, std::move(image)).second) {
      throw InputError(label, "duplicate image id " + std::to_string(id), ln);
    }
  }
  return images;
}

std::map<Point3DId, Point3D> ReadPoints3DText(std::istream& in, const std::string& label) {
  std::map<Point3DId, Point3D> points;
  LineReader reader{in, label, 0, {}};
  while (reader.NextDataLine()) {
    const std::size_t ln = reader.line_number;
    const auto tokens = SplitWhitespace(reader.line);
    if (tokens.size() < 8 || (tokens.size() - 8) % 2 != 0) {
      throw InputError(label,
                       "expected 'POINT3D_ID X Y Z R G B ERROR' followed by pairs "
                       "'IMAGE_ID POINT2D_IDX'",
                       ln);
    }
    Point3D point;
    const std::uint64_t id = ParseUnsigned(tokens[0], "POINT3D_ID", label, ln);
    if (id == kInvalidPoint3DIdBinary) throw InputError(label, "point id out of range", ln);
    point.point3d_id = Point3DId(id);
    for (int i = 0; i < 3; ++i) point.xyz[i] = ParseDouble(tokens[1 + i], "X/Y/Z", label, ln);
    for (int i = 0; i < 3; ++i) {
      const std::uint64_t c = ParseUnsigned(tokens[4 + i], "R/G/B", label, ln);
      if (c > 255) throw InputError(label, "colour component above 255", ln);
      point.rgb[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(c);
    }
    point.error = ParseDouble(tokens[7], "ERROR", label, ln);
    point.track.reserve((tokens.size() - 8) / 2);
    for (std::size_t i = 8; i < tokens.size(); i += 2) {
      const std::uint64_t image_id = ParseUnsigned(tokens[i], "IMAGE_ID", label, ln);
      const std::uint64_t idx = ParseUnsigned(tokens[i + 1], "POINT2D_IDX", label, ln);
      if (image_id >= std::numeric_limits<std::uint32_t>::max() ||
          idx > std::numeric_limits<std::uint32_t>::max()) {
        throw InputError(label, "track element out of range", ln);
      }
      point.track.push_back(
          {ImageId(static_cast<std::uint32_t>(image_id)), static_cast<std::uint32_t>(idx)});
    }
    if (!points.emplace(point.point3d_id, std::move(point)).second) {
      throw InputError(label, "duplicate point id " + std::to_string(id), ln);
    }
  }
  return points;
}

// -------------------------------------------------------------- binary readers

std::map<CameraId, Camera> ReadCamerasBinary(std::istream& in, const std::string& label) {
  BinaryReader reader(in, label);
  std::map<CameraId, Camera> cameras;
  const std::uint64_t count = reader.ReadU64();
  reader.CheckCount(count, kMinCameraBytes, "camera");
  for (std::uint64_t i = 0; i < count; ++i) {
    const std::uint32_t id = reader.ReadU32();
    const std::int32_t model_id = reader.ReadI32();
    const std::uint64_t width = reader.ReadU64();
    const std::uint64_t height = reader.ReadU64();
    Camera camera = MakeCamera(id, model_id, width, height,
                               label + " (camera record " + std::to_string(i) + ")", 0);
    const int n = CameraModelNumParams(camera.model);
    for (int p = 0; p < n; ++p) {
      const double v = reader.ReadF64();
      if (!std::isfinite(v)) {
        throw InputError(label, "camera " + std::to_string(id) + " has a non-finite parameter");
      }
      camera.params.push_back(v);
    }
    if (!cameras.emplace(camera.camera_id, camera).second) {
      throw InputError(label, "duplicate camera id " + std::to_string(id));
    }
  }
  reader.ExpectEnd();
  return cameras;
}

std::map<ImageId, Image> ReadImagesBinary(std::istream& in, const std::string& label) {
  BinaryReader reader(in, label);
  std::map<ImageId, Image> images;
  const std::uint64_t count = reader.ReadU64();
  reader.CheckCount(count, kMinImageBytes, "image");
  for (std::uint64_t i = 0; i < count; ++i) {
    Image image;
    const std::uint32_t id = reader.ReadU32();
    if (id == ImageId::kInvalidValue) throw InputError(label, "image id out of range");
    image.image_id = ImageId(id);
    double q[4];
    for (double& v : q) v = reader.ReadF64();
    image.cam_from_world.rotation = QuaternionFromWxyz(
        q[0], q[1], q[2], q[3], label + " (image " + std::to_string(id) + ")", 0);
    for (int k = 0; k < 3; ++k) image.cam_from_world.translation[k] = reader.ReadF64();
    if (!image.cam_from_world.translation.allFinite()) {
      throw InputError(label, "image " + std::to_string(id) + " has a non-finite translation");
    }
    image.camera_id = CameraId(reader.ReadU32());
    image.name = reader.ReadNulTerminatedString("the name of image " + std::to_string(id));
    CheckImageName(image.name, label, 0);
    const std::uint64_t num_points2d = reader.ReadU64();
    reader.CheckCount(num_points2d, kPoint2DBytes, "2D point (image " + std::to_string(id) + ")");
    image.points2d.resize(num_points2d);
    for (Point2D& p : image.points2d) {
      p.xy.x() = reader.ReadF64();
      p.xy.y() = reader.ReadF64();
      if (!p.xy.allFinite()) {
        throw InputError(label, "image " + std::to_string(id) + " has a non-finite 2D point");
      }
      const std::uint64_t point_id = reader.ReadU64();
      if (point_id != kInvalidPoint3DIdBinary) p.point3d_id = Point3DId(point_id);
    }
    if (!images.emplace(image.image_id, std::move(image)).second) {
      throw InputError(label, "duplicate image id " + std::to_string(id));
    }
  }
  reader.ExpectEnd();
  return images;
}

std::map<Point3DId, Point3D> ReadPoints3DBinary(std::istream& in, const std::string& label) {
  BinaryReader reader(in, label);
  std::map<Point3DId, Point3D> points;
  const std::uint64_t count = reader.ReadU64();
  reader.CheckCount(count, kMinPoint3DBytes, "3D point");
  for (std::uint64_t i = 0; i < count; ++i) {
    Point3D point;
    const std::uint64_t id = reader.ReadU64();
    if (id == kInvalidPoint3DIdBinary) throw InputError(label, "point id out of range");
    point.point3d_id = Point3DId(id);
    for (int k = 0; k < 3; ++k) point.xyz[k] = reader.ReadF64();
    for (auto& c : point.rgb) c = reader.ReadU8();
    point.error = reader.ReadF64();
    if (!point.xyz.allFinite() || !std::isfinite(point.error)) {
      throw InputError(label, "3D point " + std::to_string(id) + " has a non-finite value");
    }
    const std::uint64_t track_length = reader.ReadU64();
    reader.CheckCount(track_length, kTrackElementBytes,
                      "track element (point " + std::to_string(id) + ")");
    point.track.resize(track_length);
    for (TrackElement& e : point.track) {
      e.image_id = ImageId(reader.ReadU32());
      e.point2d_idx = reader.ReadU32();
    }
    if (!points.emplace(point.point3d_id, std::move(point)).second) {
      throw InputError(label, "duplicate point id " + std::to_string(id));
    }
  }
  reader.ExpectEnd();
  return points;
}

// --------------------------------------------------------------------- writers

void WriteCamerasText(const Reconstruction& reconstruction, std::ostream& out) {
  SetPrecision(out);
  out << "# Camera list with one line of data per camera:\n"
      << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      << "# Number of cameras: " << reconstruction.cameras.size() << "\n";
  for (const auto& [id, camera] : reconstruction.cameras) {
    out << id.value << " " << CameraModelName(camera.model) << " " << camera.width << " "
        << camera.height;
    for (double p : camera.params) out << " " << p;
    out << "\n";
  }
}

void WriteImagesText(const Reconstruction& reconstruction, std::ostream& out) {
  SetPrecision(out);
  out << "# Image list with two lines of data per image:\n"
      << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      << "# Number of images: " << reconstruction.images.size()
      << ", mean observations per image: " << reconstruction.MeanObservationsPerImage() << "\n";
  for (const auto& [id, image] : reconstruction.images) {
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    const Eigen::Vector3d& t = image.cam_from_world.translation;
    out << id.value << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x()
        << " " << t.y() << " " << t.z() << " " << image.camera_id.value << " " << image.name
        << "\n";
    bool first = true;
    for (const Point2D& p : image.points2d) {
      if (!first) out << " ";
      first = false;
      out << p.xy.x() << " " << p.xy.y() << " ";
      if (p.point3d_id.IsValid()) {
        out << p.point3d_id.value;
      } else {
        out << -1;
      }
    }
    out << "\n";
  }
}

void WritePoints3DText(const Reconstruction& reconstruction, std::ostream& out) {
  SetPrecision(out);
  out << "# 3D point list with one line of data per point:\n"
      << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      << "# Number of points: " << reconstruction.points3d.size()
      << ", mean track length: " << reconstruction.MeanTrackLength() << "\n";
  for (const auto& [id, point] : reconstruction.points3d) {
    out << id.value << " " << point.xyz.x() << " " << point.xyz.y() << " " << point.xyz.z() << " "
        << int(point.rgb[0]) << " " << int(point.rgb[1]) << " " << int(point.rgb[2]) << " "
        << point.error;
    for (const TrackElement& e : point.track)
      out << " " << e.image_id.value << " " << e.point2d_idx;
    out << "\n";
  }
}

void WriteCamerasBinary(const Reconstruction& reconstruction, std::ostream& out) {
  WriteU64(out, reconstruction.cameras.size());
  for (const auto& [id, camera] : reconstruction.cameras) {
    WriteU32(out, id.value);
    WriteI32(out, static_cast<std::int32_t>(camera.model));
    WriteU64(out, camera.width);
    WriteU64(out, camera.height);
    for (double p : camera.params) WriteF64(out, p);
  }
}

void WriteImagesBinary(const Reconstruction& reconstruction, std::ostream& out) {
  WriteU64(out, reconstruction.images.size());
  for (const auto& [id, image] : reconstruction.images) {
    WriteU32(out, id.value);
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    for (double v : {q.w(), q.x(), q.y(), q.z()}) WriteF64(out, v);
    for (int k = 0; k < 3; ++k) WriteF64(out, image.cam_from_world.translation[k]);
    WriteU32(out, image.camera_id.value);
    out.write(image.name.c_str(), static_cast<std::streamsize>(image.name.size() + 1));
    WriteU64(out, image.points2d.size());
    for (const Point2D& p : image.points2d) {
      WriteF64(out, p.xy.x());
      WriteF64(out, p.xy.y());
      WriteU64(out, p.point3d_id.IsValid() ? p.point3d_id.value : kInvalidPoint3DIdBinary);
    }
  }
}

void WritePoints3DBinary(const Reconstruction& reconstruction, std::ostream& out) {
  WriteU64(out, reconstruction.points3d.size());
  for (const auto& [id, point] : reconstruction.points3d) {
    WriteU64(out, id.value);
    for (int k = 0; k < 3; ++k) WriteF64(out, point.xyz[k]);
    for (std::uint8_t c : point.rgb) WriteU8(out, c);
    WriteF64(out, point.error);
    WriteU64(out, point.track.size());
    for (const TrackElement& e : point.track) {
      WriteU32(out, e.image_id.value);
      WriteU32(out, e.point2d_idx);
    }
  }
}

// ---------------------------------------------------------------------- folders

namespace {

bool HasModelFiles(const std::filesystem::path& dir, const char* ext) {
  std::error_code ec;
  for (const char* stem : {"cameras", "images", "points3D"}) {
    if (!std::filesystem::is_regular_file(dir / (std::string(stem) + ext), ec)) return false;
  }
  return true;
}

// Subfolders in COLMAP's numbering order: numbered ones by number, then the rest by name.
std::vector<std::filesystem::path> SubfoldersInOrder(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> folders;
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return folders;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.is_directory(ec)) folders.push_back(entry.path());
  }
  auto key = [](const std::filesystem::path& p) {
    const std::string name = p.filename().string();
    const bool numbered = !name.empty() && name.size() < 10 &&
                          name.find_first_not_of("0123456789") == std::string::npos;
    return std::tuple(!numbered, numbered ? std::stoul(name) : 0ul, name);
  };
  std::sort(folders.begin(), folders.end(),
            [&](const auto& a, const auto& b) { return key(a) < key(b); });
  return folders;
}

// The images a model registers: images.bin's count, or images.txt's image lines (every
// other line that is not a comment). Throws InputError when the file cannot be read.
std::size_t NumRegisteredImages(const std::filesystem::path& model_dir) {
  const bool binary = DetectModelFormat(model_dir) == ModelFormat::kBinary;
  const std::filesystem::path file = model_dir / (binary ? "images.bin" : "images.txt");
  std::ifstream in = OpenForReading(file, binary);
  if (binary) return BinaryReader(in, file.string()).ReadU64();
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);)
    if (line.empty() || line[0] != '#') ++lines;
  return (lines + 1) / 2;
}

}  // namespace

bool IsModelFolder(const std::filesystem::path& dir) {
  return HasModelFiles(dir, ".bin") || HasModelFiles(dir, ".txt");
}

ModelFormat DetectModelFormat(const std::filesystem::path& model_dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(model_dir, ec)) {
    throw InputError(model_dir.string(), "model folder not found");
  }
  if (HasModelFiles(model_dir, ".bin")) return ModelFormat::kBinary;
  if (HasModelFiles(model_dir, ".txt")) return ModelFormat::kText;
  throw InputError(model_dir.string(),
                   "not a COLMAP model folder: needs cameras, images and points3D as .bin or .txt");
}

ModelFolderChoice FindModelFolder(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) {
    throw InputError(path.string(), "COLMAP model folder not found");
  }
  if (IsModelFolder(path)) return {path, ""};
  // A workspace root (`sparse/0`, ...), its `sparse/` folder, or a folder of models.
  std::vector<std::filesystem::path> places = {path / "sparse"};
  for (const auto& sub : SubfoldersInOrder(path / "sparse")) places.push_back(sub);
  for (const auto& sub : SubfoldersInOrder(path)) {
    if (sub.filename() != "sparse") places.push_back(sub);
  }
  std::vector<std::pair<std::filesystem::path, std::size_t>> models;
  std::string unreadable;
  for (const auto& place : places) {
    if (!IsModelFolder(place)) continue;
    try {
      models.emplace_back(place, NumRegisteredImages(place));
    } catch (const InputError& e) {  // a damaged model does not hide the others
      unreadable += std::string(unreadable.empty() ? "" : "; ") + e.what();
    }
  }
  if (models.empty()) {
    throw InputError(path.string(),
                     "no COLMAP model found: looked for cameras, images and points3D (.bin or "
                     ".txt) in this folder, in sparse/, and in the subfolders of both" +
                         (unreadable.empty() ? "" : " (unreadable: " + unreadable + ")"));
  }
  const std::string skipped = unreadable.empty() ? "" : "; skipped " + unreadable;
  if (models.size() == 1) {
    return {models[0].first, "using the COLMAP model in " + models[0].first.string() + skipped};
  }
  std::size_t best = 0;
  std::string found;
  for (std::size_t k = 0; k < models.size(); ++k) {
    if (models[k].second > models[best].second) best = k;
    found += (k ? ", " : "") + models[k].first.string() + " (" + std::to_string(models[k].second) +
             " images)";
  }
  return {models[best].first,
          "found " + std::to_string(models.size()) + " COLMAP models: " + found + "; using " +
              models[best].first.string() + ", which registers the most images" + skipped};
}

Reconstruction ReadModel(const std::filesystem::path& model_dir, ModelFormat format) {
  const bool binary = format == ModelFormat::kBinary;
  const std::string ext = binary ? ".bin" : ".txt";
  auto path = [&](const char* stem) { return model_dir / (std::string(stem) + ext); };
  Reconstruction r;
  {
    std::ifstream in = OpenForReading(path("cameras"), binary);
    r.cameras = binary ? ReadCamerasBinary(in, path("cameras").string())
                       : ReadCamerasText(in, path("cameras").string());
  }
  {
    std::ifstream in = OpenForReading(path("images"), binary);
    r.images = binary ? ReadImagesBinary(in, path("images").string())
                      : ReadImagesText(in, path("images").string());
  }
  {
    std::ifstream in = OpenForReading(path("points3D"), binary);
    r.points3d = binary ? ReadPoints3DBinary(in, path("points3D").string())
                        : ReadPoints3DText(in, path("points3D").string());
  }
  ValidateReconstruction(r, model_dir.string());
  return r;
}

LoadedModel ReadModel(const std::filesystem::path& path) {
  const ModelFolderChoice found = FindModelFolder(path);
  const std::filesystem::path& model_dir = found.folder;
  LoadedModel loaded;
  loaded.folder = model_dir;
  loaded.choice = found.choice;
  loaded.format = DetectModelFormat(model_dir);
  loaded.reconstruction = ReadModel(model_dir, loaded.format);
  std::error_code ec;
  for (const char* name : {"rigs.bin", "rigs.txt", "frames.bin", "frames.txt"}) {
    if (std::filesystem::exists(model_dir / name, ec))
      loaded.ignored_files.push_back(model_dir / name);
  }
  return loaded;
}

void WriteModel(const Reconstruction& reconstruction, const std::filesystem::path& model_dir,
                ModelFormat format) {
  std::filesystem::create_directories(model_dir);
  const bool binary = format == ModelFormat::kBinary;
  const std::string ext = binary ? ".bin" : ".txt";
  WriteFileAtomically(
      model_dir / ("cameras" + ext),
      [&](std::ostream& out) {
        binary ? WriteCamerasBinary(reconstruction, out) : WriteCamerasText(reconstruction, out);
      },
      binary);
  WriteFileAtomically(
      model_dir / ("images" + ext),
      [&](std::ostream& out) {
        binary ? WriteImagesBinary(reconstruction, out) : WriteImagesText(reconstruction, out);
      },
      binary);
  WriteFileAtomically(
      model_dir / ("points3D" + ext),
      [&](std::ostream& out) {
        binary ? WritePoints3DBinary(reconstruction, out) : WritePoints3DText(reconstruction, out);
      },
      binary);
}

void ValidateReconstruction(const Reconstruction& r, const std::string& label) {
  for (const auto& [id, camera] : r.cameras) {
    try {
      camera.Check();
    } catch (const std::invalid_argument& e) {
      throw InputError(label, "camera " + std::to_string(id.value) + ": " + e.what());
    }
  }
  for (const auto& [id, image] : r.images) {
    if (!r.cameras.count(image.camera_id)) {
      throw InputError(label, "image " + std::to_string(id.value) + " ('" + image.name +
                                  "') refers to camera " + std::to_string(image.camera_id.value) +
                                  ", which is not in the model");
    }
    for (const Point2D& p : image.points2d) {
      if (p.point3d_id.IsValid() && !r.points3d.count(p.point3d_id)) {
        throw InputError(label, "image " + std::to_string(id.value) + " observes 3D point " +
                                    std::to_string(p.point3d_id.value) +
                                    ", which is not in the model");
      }
    }
  }
  for (const auto& [id, point] : r.points3d) {
    for (const TrackElement& e : point.track) {
      const auto it = r.images.find(e.image_id);
      if (it == r.images.end()) {
        throw InputError(label, "3D point " + std::to_string(id.value) + " is seen by image " +
                                    std::to_string(e.image_id.value) +
                                    ", which is not in the model");
      }
      if (e.point2d_idx >= it->second.points2d.size()) {
        throw InputError(label, "3D point " + std::to_string(id.value) + " refers to feature " +
                                    std::to_string(e.point2d_idx) + " of image " +
                                    std::to_string(e.image_id.value) + ", which has only " +
                                    std::to_string(it->second.points2d.size()));
      }
    }
  }
}

}  // namespace texlume::sfm
