#include "btf/btf.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numeric>

#include "core/check.h"
#include "core/cubic_interpolation.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/image_io.h"
#include "core/json_io.h"
#include "ptm/exr_io.h"

namespace texlume::btf {
namespace fs = std::filesystem;
namespace {

constexpr int kMaxSide = 16384;
constexpr std::size_t kMaxDirections = 4096;
/// The data matrix (texels x views * lights * 3, doubles) must stay below this.
constexpr double kMaxDataBytes = 8.0 * 1024 * 1024 * 1024;
// The most view-light images a capture may hold (a dense BTF measurement has ~6,500).
constexpr std::size_t kMaxImages = 65536;

std::vector<Eigen::Vector3d> ReadDirections(const nlohmann::json& j, const char* key,
                                            const std::string& label) {
  if (!j.contains(key) || !j[key].is_array() || j[key].empty())
    throw InputError(label, std::string("has no '") + key + "' list of directions");
  if (j[key].size() > kMaxDirections)
    throw InputError(label,
                     std::string("has more than ") + std::to_string(kMaxDirections) + " " + key);
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < j[key].size(); ++i) {
    const nlohmann::json& d = j[key][i];
    const std::string which = std::string(key) + "[" + std::to_string(i) + "]";
    if (!d.is_array() || d.size() != 3 || !d[0].is_number() || !d[1].is_number() ||
        !d[2].is_number())
      throw InputError(label, which + " is not a direction [x, y, z]");
    const Eigen::Vector3d v(d[0].get<double>(), d[1].get<double>(), d[2].get<double>());
    if (!v.allFinite() || std::abs(v.norm() - 1.0) > 1e-3)
      throw InputError(label, which + " is not a unit vector");
    if (v.z() <= 0.0) throw InputError(label, which + " is not above the sample (z <= 0)");
    out.push_back(v.normalized());
  }
  return out;
}

// The capture's image name for (view, light): `pattern` is literal text with "%%"
// and exactly two integer fields "%d" (or "%0<width>d", width at most 9), the view
// then the light. It is expanded here, never handed to printf, so nothing in
// btf.json can act as a format string. Empty when the pattern is not of that form.
std::string FileName(const std::string& pattern, std::size_t view, std::size_t light) {
  const std::array<std::size_t, 2> values = {view, light};
  std::string name;
  std::size_t field = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      name.push_back(pattern[i]);
      continue;
    }
    if (++i < pattern.size() && pattern[i] == '%') {
      name.push_back('%');
      continue;
    }
    const bool zero_pad = i < pattern.size() && pattern[i] == '0';
    if (zero_pad) ++i;
    std::size_t width = 0;
    if (i < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i]))) {
      width = static_cast<std::size_t>(pattern[i++] - '0');
    }
    if (i >= pattern.size() || pattern[i] != 'd' || field >= values.size()) return {};
    std::string digits = std::to_string(values[field++]);
    if (digits.size() < width) digits.insert(0, width - digits.size(), zero_pad ? '0' : ' ');
    name += digits;
  }
  return field == values.size() ? name : std::string();
}

nlohmann::json DirectionsJson(const std::vector<Eigen::Vector3d>& directions) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& d : directions) out.push_back({d.x(), d.y(), d.z()});
  return out;
}

}  // namespace

BtfCapture ParseBtfJson(const nlohmann::json& j, const fs::path& dir, const std::string& label) {
  BtfCapture capture;
  auto integer = [&](const char* key) {
    if (!j.contains(key) || !j[key].is_number_integer())
      throw InputError(label, std::string("has no integer '") + key + "'");
    const long long v = j[key].get<long long>();
    if (v < 1 || v > kMaxSide)
      throw InputError(label, std::string("'") + key + "' must be in [1, " +
                                  std::to_string(kMaxSide) + "], not " + std::to_string(v));
    return static_cast<int>(v);
  };
  if (!j.is_object()) throw InputError(label, "is not a JSON object");
  if (j.contains("size")) {
    capture.width = capture.height = integer("size");
  } else {
    capture.width = integer("width");
    capture.height = integer("height");
  }
  if (!j.contains("texel_size") || !j["texel_size"].is_number() ||
      !(j["texel_size"].get<double>() > 0.0))
    throw InputError(label, "has no positive 'texel_size'");
  capture.texel_size = j["texel_size"].get<double>();
  capture.views = ReadDirections(j, "views", label);
  capture.lights = ReadDirections(j, "lights", label);
  if (capture.views.size() * capture.lights.size() > kMaxImages)
    throw InputError(label, std::to_string(capture.views.size()) + " views x " +
                                std::to_string(capture.lights.size()) + " lights is more than " +
                                std::to_string(kMaxImages) + " images");
  if (!j.contains("file_pattern") || !j["file_pattern"].is_string())
    throw InputError(label, "has no 'file_pattern' (for example view_%02d_light_%02d.png)");
  const std::string pattern = j["file_pattern"].get<std::string>();
  const double bytes = static_cast<double>(capture.width) * capture.height *
                       static_cast<double>(capture.views.size() * capture.lights.size()) * 3 * 8;
  if (bytes > kMaxDataBytes)
    throw InputError(label, "a capture of this size needs " +
                                std::to_string(static_cast<long long>(bytes / (1 << 20))) +
                                " MiB to factorise, more than the " +
                                std::to_string(static_cast<long long>(kMaxDataBytes / (1 << 20))) +
                                " MiB allowed");
  for (std::size_t a = 0; a < capture.views.size(); ++a)
    for (std::size_t b = 0; b < capture.lights.size(); ++b) {
      const std::string name = FileName(pattern, a, b);
      if (name.empty()) {
        throw InputError(label, "file_pattern '" + pattern +
                                    "' must be a file name with two integer fields %d (or "
                                    "%02d), the view's index then the light's");
      }
      capture.files.push_back(ContainedPath(dir, name, label, "file_pattern"));
    }
  return capture;
}

BtfCapture ReadBtfCapture(const fs::path& dir) {
  const fs::path json_path = dir / "btf.json";
  BtfCapture capture = ParseBtfJson(ReadJsonFile(json_path), dir, json_path.string());
  for (std::size_t k = 0; k < capture.files.size(); ++k) {
    const fs::path& file = capture.files[k];
    if (!fs::exists(file))
      throw InputError(file.string(), "is missing: the capture has no image for view " +
                                          std::to_string(k / capture.lights.size()) +
                                          " and light " +
                                          std::to_string(k % capture.lights.size()));
    cv::Mat rgb = ReadPhotoRgb(file);
    if (rgb.cols != capture.width || rgb.rows != capture.height)
      throw InputError(file.string(), "is " + std::to_string(rgb.cols) + " x " +
                                          std::to_string(rgb.rows) + ", not " +
                                          std::to_string(capture.width) + " x " +
                                          std::to_string(capture.height) + " as btf.json says");
    for (auto it = rgb.begin<cv::Vec3f>(); it != rgb.end<cv::Vec3f>(); ++it)
      for (int c = 0; c < 3; ++c) (*it)[c] = SrgbToLinear((*it)[c]);
    capture.images.push_back(std::move(rgb));
  }
  return capture;
}

BtfFactorisation FactoriseBtf(const BtfCapture& capture, int components,
                              const ProgressCallback& progress) {
  const std::size_t texels =
      static_cast<std::size_t>(capture.width) * static_cast<std::size_t>(capture.height);
  const std::size_t columns = capture.images.size() * 3;
  TEXLUME_CHECK(capture.images.size() == capture.views.size() * capture.lights.size() && texels > 0,
                "a capture has one image per view and light");
  const std::size_t most = std::min(texels, columns);
  if (components < 1 || static_cast<std::size_t>(components) > most)
    throw OptionError("--components must be in [1, " + std::to_string(most) +
                      "]: the capture has " + std::to_string(texels) + " texels and " +
                      std::to_string(capture.images.size()) + " view-light pairs x 3 channels");
  // The data matrix F: one row per texel, one column per (view, light, channel).
  Eigen::MatrixXd f(texels, columns);
  for (std::size_t k = 0; k < capture.images.size(); ++k) {
    const cv::Mat& image = capture.images[k];
    std::size_t t = 0;
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x, ++t) {
        const cv::Vec3f& p = image.at<cv::Vec3f>(y, x);
        for (int c = 0; c < 3; ++c) f(static_cast<Eigen::Index>(t), k * 3 + c) = p[c];
      }
  }
  if (progress) progress("BTF SVD", 1, 3);
  // SVD through the Gram matrix F^T F = V S^2 V^T (columns << texels):
  // p_i = v_i, g_i = F v_i = s_i u_i (paper 004 §III).
  const Eigen::MatrixXd gram = f.transpose() * f;
  if (progress) progress("BTF SVD", 2, 3);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(gram);
  if (eigen.info() != Eigen::Success) throw std::runtime_error("FactoriseBtf: the SVD failed");
  const Eigen::Index m = static_cast<Eigen::Index>(columns);
  BtfFactorisation out;
  out.width = capture.width;
  out.height = capture.height;
  out.texel_size = capture.texel_size;
  out.views = capture.views;
  out.lights = capture.lights;
  for (Eigen::Index i = m - 1; i >= 0; --i)  // eigenvalues come smallest first
    out.singular_values.push_back(std::sqrt(std::max(0.0, eigen.eigenvalues()[i])));
  Eigen::MatrixXd v(m, components);
  for (int i = 0; i < components; ++i) {
    Eigen::VectorXd column = eigen.eigenvectors().col(m - 1 - i);
    // Sign convention (deterministic output): the largest entry is positive.
    Eigen::Index at = 0;
    column.cwiseAbs().maxCoeff(&at);
    if (column[at] < 0) column = -column;
    v.col(i) = column;
  }
  out.appearance = v.cast<float>();
  out.geometry = (f * v).cast<float>();
  if (progress) progress("BTF SVD", 3, 3);
  return out;
}

std::vector<SvdError> SvdErrorTable(const BtfFactorisation& factorisation,
                                    const std::vector<int>& components) {
  const std::vector<double>& s = factorisation.singular_values;
  const double entries = static_cast<double>(factorisation.NumTexels()) *
                         static_cast<double>(std::max<std::size_t>(s.size(), 1));
  double total = 0.0;
  for (double v : s) total += v * v;
  std::vector<SvdError> table;
  for (int n : components) {
    double residual = 0.0;
    for (std::size_t i = static_cast<std::size_t>(std::max(n, 0)); i < s.size(); ++i)
      residual += s[i] * s[i];
    table.push_back(
        {n, std::sqrt(residual / entries), total > 0 ? std::sqrt(residual / total) : 0.0});
  }
  return table;
}

std::vector<SvdError> SvdErrorTable(const BtfFactorisation& factorisation) {
  std::vector<int> ns;
  for (int k = 1; k < factorisation.Components(); k *= 2) ns.push_back(k);
  ns.push_back(factorisation.Components());
  return SvdErrorTable(factorisation, ns);
}

BtfFactorisation ReadOrFactoriseBtf(const fs::path& dir, int components,
                                    const ProgressCallback& progress) {
  if (fs::exists(dir / "btf_svd.json")) return ReadBtfFactorisation(dir);
  if (!fs::exists(dir / "btf.json"))
    throw InputError(dir.string(),
                     "is not a BTF sample folder (it has neither btf.json, a capture, nor "
                     "btf_svd.json, a factorisation)");
  return FactoriseBtf(ReadBtfCapture(dir), components, progress);
}

std::vector<std::pair<std::size_t, double>> DirectionWeights(
    const std::vector<Eigen::Vector3d>& grid, const Eigen::Vector3d& query) {
  const Eigen::Vector3d q = query.normalized();
  std::vector<std::pair<double, std::size_t>> by_angle;
  for (std::size_t i = 0; i < grid.size(); ++i)
    by_angle.emplace_back(std::acos(std::clamp(grid[i].dot(q), -1.0, 1.0)), i);
  const std::size_t k = std::min<std::size_t>(3, by_angle.size());
  std::partial_sort(by_angle.begin(), by_angle.begin() + static_cast<std::ptrdiff_t>(k),
                    by_angle.end());
  if (by_angle.empty()) return {};
  if (by_angle[0].first < 1e-9) return {{by_angle[0].second, 1.0}};
  std::vector<std::pair<std::size_t, double>> weights;
  double sum = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    const double w = 1.0 / (by_angle[i].first * by_angle[i].first);
    weights.emplace_back(by_angle[i].second, w);
    sum += w;
  }
  for (auto& w : weights) w.second /= sum;
  return weights;
}

Eigen::MatrixX3f InterpolateAppearance(const BtfFactorisation& factorisation,
                                       const Eigen::Vector3d& view, const Eigen::Vector3d& light) {
  const int n = factorisation.Components();
  Eigen::MatrixX3f p = Eigen::MatrixX3f::Zero(n, 3);
  const std::size_t num_lights = factorisation.lights.size();
  // Below the lowest direction of a grid, the direction at that elevation (same
  // azimuth); a light there also fades linearly in l_z to 0 at the horizon, as
  // irradiance does (cos of the angle to the normal), instead of extrapolating.
  auto lift = [](const std::vector<Eigen::Vector3d>& grid, Eigen::Vector3d d) {
    double z_low = 1.0;
    for (const Eigen::Vector3d& g : grid) z_low = std::min(z_low, g.z());
    const double r = std::hypot(d.x(), d.y());
    if (d.z() >= z_low || z_low >= 1.0 || r < 1e-12) return std::make_pair(d, 1.0);
    const double fade = std::max(d.z(), 0.0) / z_low;
    const double s = std::sqrt(1.0 - z_low * z_low) / r;
    return std::make_pair(Eigen::Vector3d(d.x() * s, d.y() * s, z_low), fade);
  };
  const auto [view_used, view_fade] = lift(factorisation.views, view);
  const auto [light_used, light_fade] = lift(factorisation.lights, light);
  (void)view_fade;  // radiance does not vanish towards a grazing view
  for (const auto& [a, wa] : DirectionWeights(factorisation.views, view_used))
    for (const auto& [b, wb_grid] : DirectionWeights(factorisation.lights, light_used)) {
      const double wb = wb_grid * light_fade;
      for (int c = 0; c < 3; ++c)
        p.col(c) += static_cast<float>(wa * wb) *
                    factorisation.appearance
                        .row(static_cast<Eigen::Index>((a * num_lights + b) * 3 +
                                                       static_cast<std::size_t>(c)))
                        .transpose();
    }
  return p;
}

Eigen::MatrixX3f AppearanceUnder(const BtfFactorisation& factorisation, const Eigen::Vector3d& view,
                                 const std::vector<MaterialLight>& lights,
                                 const ptm::LightResponse& response) {
  Eigen::MatrixX3f a = Eigen::MatrixX3f::Zero(factorisation.Components(), 3);
  for (const auto& [l, intensity] : lights) {
    if (l.z() <= 0.0) continue;
    a += static_cast<float>(intensity * response.FactorAt(l.z())) *
         InterpolateAppearance(factorisation, view, l);
  }
  if (response.ambient > 0.0)
    a += static_cast<float>(response.ambient) *
         InterpolateAppearance(factorisation, view, Eigen::Vector3d::UnitZ());
  return a;
}

cv::Mat EvaluateBtf(const BtfFactorisation& factorisation, const Eigen::Vector3d& view,
                    const Eigen::Vector3d& light, int components) {
  const int n = components > 0 ? std::min(components, factorisation.Components())
                               : factorisation.Components();
  const Eigen::MatrixX3f p = InterpolateAppearance(factorisation, view, light).topRows(n);
  const Eigen::MatrixX3f rgb = factorisation.geometry.leftCols(n) * p;  // texels x 3
  cv::Mat image(factorisation.height, factorisation.width, CV_32FC3);
  Eigen::Index t = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x, ++t)
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(rgb(t, 0), rgb(t, 1), rgb(t, 2));
  return image;
}

void WriteBtfFactorisation(const BtfFactorisation& factorisation,
                           const std::vector<SvdError>& errors, const fs::path& dir) {
  fs::create_directories(dir);
  const int n = factorisation.Components();
  std::vector<cv::Mat> planes;
  std::vector<std::string> names;
  for (int i = 0; i < n; ++i) {
    cv::Mat plane(factorisation.height, factorisation.width, CV_32FC1);
    Eigen::Index t = 0;
    for (int y = 0; y < plane.rows; ++y)
      for (int x = 0; x < plane.cols; ++x, ++t)
        plane.at<float>(y, x) = factorisation.geometry(t, i);
    planes.push_back(plane);
    char name[16];
    std::snprintf(name, sizeof name, "g%02d", i);
    names.emplace_back(name);
  }
  ptm::WriteExr(dir / "geometry_maps.exr", planes, names);
  WriteFileAtomically(
      dir / "appearance.bin",
      [&](std::ostream& out) {
        for (Eigen::Index r = 0; r < factorisation.appearance.rows(); ++r)
          for (Eigen::Index i = 0; i < n; ++i) {
            const float v = factorisation.appearance(r, i);
            out.write(reinterpret_cast<const char*>(&v), sizeof v);
          }
      },
      true);
  nlohmann::json table = nlohmann::json::array();
  for (const SvdError& e : errors)
    table.push_back({{"components", e.components}, {"rms", e.rms}, {"relative", e.relative}});
  const nlohmann::json j = {
      {"format", "texlume-btf-svd-1"},
      {"width", factorisation.width},
      {"height", factorisation.height},
      {"texel_size", factorisation.texel_size},
      {"components", n},
      {"views", DirectionsJson(factorisation.views)},
      {"lights", DirectionsJson(factorisation.lights)},
      {"geometry_maps", "geometry_maps.exr"},
      {"appearance", "appearance.bin"},
      {"appearance_layout",
       "float32 little-endian, row-major ((view * lights + light) * 3 + channel) x components; "
       "linear RGB"},
      {"singular_values", factorisation.singular_values},
      {"errors", table}};
  // Written last: a folder with btf_svd.json is complete.
  WriteFileAtomically(
      dir / "btf_svd.json", [&](std::ostream& out) { out << j.dump(1) << "\n"; }, false);
}

BtfFactorisation ReadBtfFactorisation(const fs::path& dir) {
  const fs::path json_path = dir / "btf_svd.json";
  const std::string label = json_path.string();
  const nlohmann::json j = ReadJsonFile(json_path);
  if (j.value("format", "") != "texlume-btf-svd-1")
    throw InputError(label, "is not a texlume BTF factorisation (format texlume-btf-svd-1)");
  BtfFactorisation out;
  try {
    out.width = j.at("width").get<int>();
    out.height = j.at("height").get<int>();
    out.texel_size = j.at("texel_size").get<double>();
    out.singular_values = j.at("singular_values").get<std::vector<double>>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(label, std::string("is malformed: ") + e.what());
  }
  if (out.width < 1 || out.width > kMaxSide || out.height < 1 || out.height > kMaxSide)
    throw InputError(label, "width and height must be in [1, " + std::to_string(kMaxSide) + "]");
  out.views = ReadDirections(j, "views", label);
  out.lights = ReadDirections(j, "lights", label);
  const int n = j.value("components", 0);
  const std::size_t rows = out.views.size() * out.lights.size() * 3;
  if (n < 1 || static_cast<std::size_t>(n) > rows)
    throw InputError(label, "components must be in [1, " + std::to_string(rows) + "]");
  std::vector<std::string> names;
  const std::vector<cv::Mat> planes = ptm::ReadExr(dir / "geometry_maps.exr", &names);
  if (planes.size() != static_cast<std::size_t>(n))
    throw InputError(
        (dir / "geometry_maps.exr").string(),
        "has " + std::to_string(planes.size()) + " channels, not " + std::to_string(n));
  out.geometry.resize(static_cast<Eigen::Index>(out.NumTexels()), n);
  for (int i = 0; i < n; ++i) {
    const cv::Mat& plane = planes[static_cast<std::size_t>(i)];
    if (plane.cols != out.width || plane.rows != out.height)
      throw InputError((dir / "geometry_maps.exr").string(),
                       "is not " + std::to_string(out.width) + " x " + std::to_string(out.height));
    Eigen::Index t = 0;
    for (int y = 0; y < plane.rows; ++y)
      for (int x = 0; x < plane.cols; ++x, ++t) out.geometry(t, i) = plane.at<float>(y, x);
  }
  const fs::path bin = dir / "appearance.bin";
  const std::uintmax_t expected = rows * static_cast<std::size_t>(n) * sizeof(float);
  if (!fs::exists(bin) || fs::file_size(bin) != expected)
    throw InputError(bin.string(), "must hold " + std::to_string(expected) + " bytes (" +
                                       std::to_string(rows) + " x " + std::to_string(n) +
                                       " float32)");
  std::ifstream in = OpenForReading(bin, true);
  out.appearance.resize(static_cast<Eigen::Index>(rows), n);
  for (std::size_t r = 0; r < rows; ++r)
    for (int i = 0; i < n; ++i) {
      float v = 0;
      in.read(reinterpret_cast<char*>(&v), sizeof v);
      out.appearance(static_cast<Eigen::Index>(r), i) = v;
    }
  if (!in) throw InputError(bin.string(), "could not be read");
  return out;
}

void SampleGeometry(const BtfFactorisation& s, const Eigen::Vector2d& sample_px, float* out) {
  const Eigen::Index w = s.width;
  CatmullRomTaps(s.width, s.height, sample_px.x() - 0.5, sample_px.y() - 0.5)
      .Read(
          s.Components(), [&](int x, int y, int i) { return s.geometry(y * w + x, i); }, out);
}

}  // namespace texlume::btf
