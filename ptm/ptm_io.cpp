#include "ptm/ptm_io.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "ptm/exr_io.h"

namespace texlume::ptm {
namespace {

// Plausibility bounds of a .ptm file's quantisation (docs/ptm_format.md): a
// coefficient (byte - bias) * scale / 255 of a relit value in [0, 1] never needs
// more; beyond them a file relights to garbage.
constexpr double kMaxPtmScale = 1e6;  // the message below says 1e6
constexpr std::int64_t kMaxPtmBias = 1000000;

// Quantisation of one coefficient index: coefficient = (byte - bias) * scale.
struct Quantiser {
  float scale = 1.0f;
  int bias = 0;
  std::uint8_t Encode(float v) const {
    return static_cast<std::uint8_t>(std::clamp(std::lround(v / scale + bias), 0L, 255L));
  }
};

Quantiser MakeQuantiser(std::vector<float> values) {
  Quantiser q;
  if (values.empty()) return q;
  const std::size_t lo_i = values.size() / 1000, hi_i = values.size() - 1 - values.size() / 1000;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo_i),
                   values.end());
  const float lo = std::min(0.0f, values[lo_i]);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(hi_i),
                   values.end());
  const float hi = std::max(0.0f, values[hi_i]);
  q.scale = hi > lo ? (hi - lo) / 255.0f : 1.0f;
  q.bias = static_cast<int>(std::lround(-lo / q.scale));
  return q;
}

// Quantisers per coefficient index, over every texel (and channel for RGB), in
// 0-255 units.
std::array<Quantiser, 6> Quantisers(const Ptm& ptm) {
  std::array<Quantiser, 6> q;
  for (int i = 0; i < 6; ++i) {
    std::vector<float> values;
    values.reserve(ptm.NumTexels() * static_cast<std::size_t>(ptm.NumPolynomials()));
    for (std::size_t t = 0; t < ptm.NumTexels(); ++t) {
      for (int p = 0; p < ptm.NumPolynomials(); ++p)
        values.push_back(255.0f * ptm.Coefficients(t, p)[i]);
    }
    q[static_cast<std::size_t>(i)] = MakeQuantiser(std::move(values));
  }
  return q;
}

std::string ReadHeaderLine(std::istream& in, const std::string& label, std::size_t line_number) {
  std::string line;
  if (!std::getline(in, line)) {
    throw InputError(label,
                     "truncated header: line " + std::to_string(line_number) + " is missing");
  }
  if (line.size() > 4096) throw InputError(label, "header line too long", line_number);
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

}  // namespace

void WritePtm(const Ptm& ptm, std::ostream& out) {
  const auto q = Quantisers(ptm);
  out << "PTM_1.2\n"
      << (ptm.format == PtmFormat::kLrgb ? "PTM_FORMAT_LRGB" : "PTM_FORMAT_RGB") << "\n"
      << ptm.width << "\n"
      << ptm.height << "\n";
  out << std::setprecision(9);
  for (int i = 0; i < 6; ++i) out << (i ? " " : "") << q[static_cast<std::size_t>(i)].scale;
  out << "\n";
  for (int i = 0; i < 6; ++i) out << (i ? " " : "") << q[static_cast<std::size_t>(i)].bias;
  out << "\n";
  std::vector<char> row(static_cast<std::size_t>(ptm.width) * 6);
  for (int p = 0; p < ptm.NumPolynomials(); ++p) {
    for (int y = ptm.height - 1; y >= 0; --y) {  // bottom to top
      for (int x = 0; x < ptm.width; ++x) {
        const float* a = ptm.Coefficients(static_cast<std::size_t>(y) * ptm.width + x, p);
        for (int i = 0; i < 6; ++i) {
          row[static_cast<std::size_t>(x) * 6 + static_cast<std::size_t>(i)] =
              static_cast<char>(q[static_cast<std::size_t>(i)].Encode(255.0f * a[i]));
        }
      }
      out.write(row.data(), static_cast<std::streamsize>(row.size()));
    }
  }
  if (ptm.format == PtmFormat::kLrgb) {
    std::vector<char> rgb(static_cast<std::size_t>(ptm.width) * 3);
    for (int y = ptm.height - 1; y >= 0; --y) {
      for (int x = 0; x < ptm.width; ++x) {
        for (int c = 0; c < 3; ++c) {
          const float v = ptm.colour[(static_cast<std::size_t>(y) * ptm.width + x) * 3 +
                                     static_cast<std::size_t>(c)];
          rgb[static_cast<std::size_t>(x) * 3 + static_cast<std::size_t>(c)] =
              static_cast<char>(std::clamp(std::lround(255.0f * v), 0L, 255L));
        }
      }
      out.write(rgb.data(), static_cast<std::streamsize>(rgb.size()));
    }
  }
}

void WritePtmFile(const Ptm& ptm, const std::filesystem::path& path) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { WritePtm(ptm, out); }, true);
}

Ptm ReadPtm(std::istream& in, const std::string& label) {
  const std::string version = ReadHeaderLine(in, label, 1);
  if (version != "PTM_1.2" && version != "PTM_1.1") {
    throw InputError(label,
                     "not a PTM file: first line is '" + version.substr(0, 40) +
                         "', expected PTM_1.2 or PTM_1.1",
                     1);
  }
  const std::string format_name = ReadHeaderLine(in, label, 2);
  PtmFormat format;
  if (format_name == "PTM_FORMAT_LRGB") {
    format = PtmFormat::kLrgb;
  } else if (format_name == "PTM_FORMAT_RGB") {
    format = PtmFormat::kRgb;
  } else {
    throw InputError(label,
                     "unsupported PTM format '" + format_name.substr(0, 40) +
                         "' (texlume reads PTM_FORMAT_RGB and PTM_FORMAT_LRGB)",
                     2);
  }
  // Width and height may share a line or take one each.
  std::vector<std::string_view> dims;
  std::string line3 = ReadHeaderLine(in, label, 3);
  std::size_t ln = 3;
  auto tokens = SplitWhitespace(line3);
  std::string line4;
  if (tokens.size() == 1) {
    line4 = ReadHeaderLine(in, label, ++ln);
    const auto more = SplitWhitespace(line4);
    if (more.size() != 1) throw InputError(label, "expected the height", ln);
    tokens.push_back(more[0]);
  }
  if (tokens.size() != 2) throw InputError(label, "expected width and height", ln);
  const std::uint64_t width = ParseUnsigned(tokens[0], "width", label, ln);
  const std::uint64_t height = ParseUnsigned(tokens[1], "height", label, ln);
  if (width == 0 || height == 0 || width > 65536 || height > 65536) {
    throw InputError(
        label, "implausible size " + std::to_string(width) + "x" + std::to_string(height), ln);
  }
  const std::string scales_line = ReadHeaderLine(in, label, ++ln);
  const auto scale_tokens = SplitWhitespace(scales_line);
  if (scale_tokens.size() != 6) throw InputError(label, "expected 6 scales", ln);
  float scale[6];
  for (int i = 0; i < 6; ++i) {
    const double s = ParseDouble(scale_tokens[static_cast<std::size_t>(i)], "a scale", label, ln);
    if (!(s > 0.0 && s <= kMaxPtmScale)) {
      throw InputError(
          label,
          "scale " + std::string(scale_tokens[static_cast<std::size_t>(i)]) + " is not in (0, 1e6]",
          ln);
    }
    scale[i] = static_cast<float>(s);
  }
  const std::string bias_line = ReadHeaderLine(in, label, ++ln);
  const auto bias_tokens = SplitWhitespace(bias_line);
  if (bias_tokens.size() != 6) throw InputError(label, "expected 6 biases", ln);
  int bias[6];
  for (int i = 0; i < 6; ++i) {
    const std::int64_t b =
        ParseSigned(bias_tokens[static_cast<std::size_t>(i)], "a bias", label, ln);
    if (b < -kMaxPtmBias || b > kMaxPtmBias) {
      throw InputError(label,
                       "bias " + std::to_string(b) + " is not in [-" + std::to_string(kMaxPtmBias) +
                           ", " + std::to_string(kMaxPtmBias) + "]",
                       ln);
    }
    bias[i] = static_cast<int>(b);
  }

  // Payload size check before allocating.
  const std::streampos here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streampos end = in.tellg();
  in.seekg(here);
  const std::uint64_t texels = width * height;
  const std::uint64_t expected = format == PtmFormat::kLrgb ? texels * 9 : texels * 18;
  const std::uint64_t available = static_cast<std::uint64_t>(end - here);
  if (available < expected) {
    throw InputError(label, "truncated payload: " + std::to_string(width) + "x" +
                                std::to_string(height) + " " + format_name + " needs " +
                                std::to_string(expected) + " bytes, the file has " +
                                std::to_string(available));
  }
  Ptm ptm;
  ptm.Resize(format, static_cast<int>(width), static_cast<int>(height));
  std::vector<unsigned char> row(static_cast<std::size_t>(width) * 6);
  for (int p = 0; p < ptm.NumPolynomials(); ++p) {
    for (int y = ptm.height - 1; y >= 0; --y) {
      in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(row.size()));
      if (!in) throw InputError(label, "read error in the coefficients");
      for (int x = 0; x < ptm.width; ++x) {
        float* a = ptm.Coefficients(static_cast<std::size_t>(y) * ptm.width + x, p);
        for (int i = 0; i < 6; ++i) {
          a[i] = (static_cast<float>(
                      row[static_cast<std::size_t>(x) * 6 + static_cast<std::size_t>(i)]) -
                  bias[i]) *
                 scale[i] / 255.0f;
        }
      }
    }
  }
  if (format == PtmFormat::kLrgb) {
    std::vector<unsigned char> rgb(static_cast<std::size_t>(width) * 3);
    for (int y = ptm.height - 1; y >= 0; --y) {
      in.read(reinterpret_cast<char*>(rgb.data()), static_cast<std::streamsize>(rgb.size()));
      if (!in) throw InputError(label, "read error in the colour block");
      for (std::size_t i = 0; i < rgb.size(); ++i) {
        ptm.colour[static_cast<std::size_t>(y) * width * 3 + i] = rgb[i] / 255.0f;
      }
    }
  }
  return ptm;
}

Ptm ReadPtmFile(const std::filesystem::path& path) {
  std::ifstream in = OpenForReading(path, true);
  return ReadPtm(in, path.string());
}

namespace {
std::vector<std::string> ExrChannelNames(PtmFormat format) {
  std::vector<std::string> names;
  if (format == PtmFormat::kLrgb) {
    for (int i = 0; i < 6; ++i) names.push_back("L.a" + std::to_string(i));
    names.insert(names.end(), {"R", "G", "B"});
  } else {
    for (const char* c : {"R", "G", "B"})
      for (int i = 0; i < 6; ++i) names.push_back(std::string(c) + ".a" + std::to_string(i));
  }
  return names;
}
}  // namespace

void WritePtmExr(const Ptm& ptm, const std::filesystem::path& path) {
  const auto names = ExrChannelNames(ptm.format);
  std::vector<cv::Mat> planes;
  for (std::size_t c = 0; c < names.size(); ++c) {
    cv::Mat plane(ptm.height, ptm.width, CV_32FC1);
    for (int y = 0; y < ptm.height; ++y) {
      for (int x = 0; x < ptm.width; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * ptm.width + x;
        float v;
        if (ptm.format == PtmFormat::kLrgb) {
          v = c < 6 ? ptm.Coefficients(t)[c] : ptm.colour[t * 3 + (c - 6)];
        } else {
          v = ptm.Coefficients(t, static_cast<int>(c / 6))[c % 6];
        }
        plane.at<float>(y, x) = v;
      }
    }
    planes.push_back(plane);
  }
  WriteExr(path, planes, names);
}

namespace {

// The PTM in a PTM EXR's planes (named as ExrChannelNames); `label` names the file.
Ptm PtmFromExrPlanes(const std::vector<cv::Mat>& planes, const std::vector<std::string>& names,
                     const std::string& label) {
  PtmFormat format = PtmFormat::kLrgb;
  std::vector<std::string> expected;
  for (auto candidate : {PtmFormat::kLrgb, PtmFormat::kRgb}) {
    auto wanted = ExrChannelNames(candidate), sorted_names = names;
    std::sort(wanted.begin(), wanted.end());
    std::sort(sorted_names.begin(), sorted_names.end());
    if (wanted == sorted_names) {
      format = candidate;
      expected = ExrChannelNames(candidate);
    }
  }
  if (expected.empty()) {
    throw InputError(label, "not a texlume PTM EXR: unexpected channel names");
  }
  Ptm ptm;
  ptm.Resize(format, planes[0].cols, planes[0].rows);
  for (std::size_t c = 0; c < expected.size(); ++c) {
    const auto it = std::find(names.begin(), names.end(), expected[c]);
    const cv::Mat& plane = planes[static_cast<std::size_t>(it - names.begin())];
    for (int y = 0; y < ptm.height; ++y) {
      for (int x = 0; x < ptm.width; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * ptm.width + x;
        const float v = plane.at<float>(y, x);
        if (format == PtmFormat::kLrgb) {
          (c < 6 ? ptm.Coefficients(t)[c] : ptm.colour[t * 3 + (c - 6)]) = v;
        } else {
          ptm.Coefficients(t, static_cast<int>(c / 6))[c % 6] = v;
        }
      }
    }
  }
  return ptm;
}

}  // namespace

Ptm ReadPtmExr(const std::filesystem::path& path) {
  std::vector<std::string> names;
  const auto planes = ReadExr(path, &names);  // OpenEXR keeps channels sorted by name
  return PtmFromExrPlanes(planes, names, path.string());
}

Ptm ReadPtmExrBytes(std::string_view bytes, const std::string& label) {
  std::vector<std::string> names;
  const auto planes = ReadExrBytes(bytes, label, &names);
  return PtmFromExrPlanes(planes, names, label);
}

WebPlanes QuantiseWebPlanes(const Ptm& ptm) {
  // OpenLIME's PTM basis order (1, x, y, x^2, xy, y^2) in texlume's coefficient indices.
  constexpr int kWebOrder[6] = {5, 3, 4, 0, 2, 1};
  std::vector<std::vector<float>> planes;  // each: one value per texel
  auto add_plane = [&](auto value_of_texel) {
    std::vector<float>& p = planes.emplace_back(ptm.NumTexels());
    for (std::size_t t = 0; t < ptm.NumTexels(); ++t) p[t] = value_of_texel(t);
  };
  if (ptm.format == PtmFormat::kLrgb) {
    for (std::size_t c = 0; c < 3; ++c)
      add_plane([&](std::size_t t) { return ptm.colour[t * 3 + c]; });
    for (int i : kWebOrder) add_plane([&](std::size_t t) { return ptm.Coefficients(t)[i]; });
  } else {
    for (int i : kWebOrder)
      for (int c = 0; c < 3; ++c)
        add_plane([&](std::size_t t) { return ptm.Coefficients(t, c)[i]; });
  }
  WebPlanes web;
  for (const auto& p : planes) {
    const auto [lo_it, hi_it] = std::minmax_element(p.begin(), p.end());
    const float lo = *lo_it, hi = *hi_it;
    web.scales.push_back(hi > lo ? hi - lo : 1.0f);
    web.biases.push_back(-lo / web.scales.back());
  }
  for (std::size_t j = 0; j * 3 < planes.size(); ++j) {
    cv::Mat& image = web.images.emplace_back(ptm.height, ptm.width, CV_8UC3);
    for (int y = 0; y < ptm.height; ++y) {
      for (int x = 0; x < ptm.width; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * ptm.width + x;
        cv::Vec3b& px = image.at<cv::Vec3b>(y, x);
        for (std::size_t c = 0; c < 3; ++c) {
          const std::size_t k = j * 3 + c;
          const float v = (planes[k][t] / web.scales[k] + web.biases[k]) * 255.0f;
          px[2 - c] = static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));  // BGR
        }
      }
    }
  }
  return web;
}

nlohmann::json WebPlanes::Info(const Ptm& ptm) const {
  return {{"width", ptm.width},
          {"height", ptm.height},
          {"type", "ptm"},
          {"colorspace", ptm.format == PtmFormat::kLrgb ? "lrgb" : "rgb"},
          {"nplanes", scales.size()},
          {"materials", nlohmann::json::array({{{"scale", scales}, {"bias", biases}}})}};
}

int WriteRelightWeb(const Ptm& ptm, const std::filesystem::path& dir, int jpeg_quality) {
  std::filesystem::create_directories(dir);
  const WebPlanes web = QuantiseWebPlanes(ptm);
  nlohmann::json info = web.Info(ptm);
  info["format"] = "jpg";
  info["quality"] = jpeg_quality;
  for (std::size_t j = 0; j < web.images.size(); ++j) {
    std::vector<unsigned char> bytes;
    cv::imencode(".jpg", web.images[j], bytes, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
    WriteFileAtomically(
        dir / ("plane_" + std::to_string(j) + ".jpg"),
        [&](std::ostream& out) {
          out.write(reinterpret_cast<const char*>(bytes.data()),
                    static_cast<std::streamsize>(bytes.size()));
        },
        true);
  }
  WriteFileAtomically(
      dir / "info.json", [&](std::ostream& out) { out << info.dump(2) << "\n"; }, false);
  return static_cast<int>(web.images.size()) + 1;
}

Ptm ReadPtmAnyFormat(const std::filesystem::path& path) {
  return LowerCaseExtension(path) == ".exr" ? ReadPtmExr(path) : ReadPtmFile(path);
}

}  // namespace texlume::ptm
