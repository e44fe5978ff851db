#include "ptm/ptm_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <iomanip>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/first_exception.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "ptm/exr_io.h"
#include "ptm/ptm_quantise.h"

namespace texlume::ptm {
namespace {

// Plausibility bounds of a .ptm file's quantisation (docs/ptm_format.md): a
// coefficient (byte - bias) * scale / 255 of a relit value in [0, 1] never needs
// more; beyond them a file relights to garbage.
constexpr double kMaxPtmScale = 1e6;  // the message below says 1e6
constexpr std::int64_t kMaxPtmBias = 1000000;

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

// What a .ptm file's header says (PTM format 1.2, Malzbender and Gelb, HP Labs 2001).
struct PtmHeader {
  std::string format_name;
  PtmFormat format = PtmFormat::kLrgb;
  bool jpeg = false;  // PTM_FORMAT_JPEG_*: one JPEG stream per plane
  int width = 0, height = 0;
  float scale[6] = {};
  int bias[6] = {};
  std::size_t line = 0;  // the last header line read
  // Byte planes: LRGB a0..a5 then R, G, B; RGB a0..a5 of R, then of G, then of B.
  int NumPlanes() const { return format == PtmFormat::kLrgb ? 9 : 18; }
  std::size_t Texels() const { return static_cast<std::size_t>(width) * height; }
};

// One plane per PtmHeader::NumPlanes, width x height bytes in the file's row order
// (the bottom row first).
using BytePlanes = std::vector<std::vector<unsigned char>>;

PtmHeader ReadPtmHeader(std::istream& in, const std::string& label) {
  PtmHeader h;
  const std::string version = ReadHeaderLine(in, label, 1);
  if (version != "PTM_1.2" && version != "PTM_1.1") {
    throw InputError(label,
                     "not a PTM file: first line is '" + version.substr(0, 40) +
                         "', expected PTM_1.2 or PTM_1.1",
                     1);
  }
  h.format_name = ReadHeaderLine(in, label, 2);
  if (h.format_name == "PTM_FORMAT_LRGB" || h.format_name == "PTM_FORMAT_JPEG_LRGB") {
    h.format = PtmFormat::kLrgb;
  } else if (h.format_name == "PTM_FORMAT_RGB" || h.format_name == "PTM_FORMAT_JPEG_RGB") {
    h.format = PtmFormat::kRgb;
  } else {
    throw InputError(label,
                     "unsupported PTM format '" + h.format_name.substr(0, 40) +
                         "' (texlume reads PTM_FORMAT_RGB, PTM_FORMAT_LRGB, PTM_FORMAT_JPEG_RGB "
                         "and PTM_FORMAT_JPEG_LRGB)",
                     2);
  }
  h.jpeg = h.format_name.rfind("PTM_FORMAT_JPEG_", 0) == 0;
  // Width and height may share a line or take one each.
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
  h.width = static_cast<int>(width);
  h.height = static_cast<int>(height);
  const std::string scales_line = ReadHeaderLine(in, label, ++ln);
  const auto scale_tokens = SplitWhitespace(scales_line);
  if (scale_tokens.size() != 6) throw InputError(label, "expected 6 scales", ln);
  for (int i = 0; i < 6; ++i) {
    const double s = ParseDouble(scale_tokens[static_cast<std::size_t>(i)], "a scale", label, ln);
    if (!(s > 0.0 && s <= kMaxPtmScale)) {
      throw InputError(
          label,
          "scale " + std::string(scale_tokens[static_cast<std::size_t>(i)]) + " is not in (0, 1e6]",
          ln);
    }
    h.scale[i] = static_cast<float>(s);
  }
  const std::string bias_line = ReadHeaderLine(in, label, ++ln);
  const auto bias_tokens = SplitWhitespace(bias_line);
  if (bias_tokens.size() != 6) throw InputError(label, "expected 6 biases", ln);
  for (int i = 0; i < 6; ++i) {
    const std::int64_t b =
        ParseSigned(bias_tokens[static_cast<std::size_t>(i)], "a bias", label, ln);
    if (b < -kMaxPtmBias || b > kMaxPtmBias) {
      throw InputError(label,
                       "bias " + std::to_string(b) + " is not in [-" + std::to_string(kMaxPtmBias) +
                           ", " + std::to_string(kMaxPtmBias) + "]",
                       ln);
    }
    h.bias[i] = static_cast<int>(b);
  }
  h.line = ln;
  return h;
}

std::uint64_t BytesLeft(std::istream& in) {
  const std::streampos here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streampos end = in.tellg();
  in.seekg(here);
  return static_cast<std::uint64_t>(end - here);
}

// Uncompressed: RGB, three blocks (R, G, B) of six interleaved coefficients per texel;
// LRGB, a block of six coefficients per texel, then one of R, G, B per texel. Streamed a
// row at a time into the PTM's floats; the file's size bounds the allocation.
Ptm ReadRawPtm(std::istream& in, const PtmHeader& h, const std::string& label) {
  const std::uint64_t expected = static_cast<std::uint64_t>(h.Texels()) * h.NumPlanes();
  const std::uint64_t available = BytesLeft(in);
  if (available < expected) {
    throw InputError(label, "truncated payload: " + std::to_string(h.width) + "x" +
                                std::to_string(h.height) + " " + h.format_name + " needs " +
                                std::to_string(expected) + " bytes, the file has " +
                                std::to_string(available));
  }
  Ptm ptm;
  ptm.Resize(h.format, h.width, h.height);
  std::vector<unsigned char> row(static_cast<std::size_t>(h.width) * 6);
  for (int q = 0; q < ptm.NumPolynomials(); ++q) {
    for (int y = h.height - 1; y >= 0; --y) {  // rows bottom to top
      in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(row.size()));
      if (!in) throw InputError(label, "read error in the coefficients");
      for (int x = 0; x < h.width; ++x) {
        float* a = ptm.Coefficients(static_cast<std::size_t>(y) * h.width + x, q);
        for (std::size_t i = 0; i < 6; ++i)
          a[i] = (static_cast<float>(row[static_cast<std::size_t>(x) * 6 + i]) - h.bias[i]) *
                 h.scale[i] / 255.0f;
      }
    }
  }
  if (h.format == PtmFormat::kLrgb) {
    std::vector<unsigned char> rgb(static_cast<std::size_t>(h.width) * 3);
    for (int y = h.height - 1; y >= 0; --y) {
      in.read(reinterpret_cast<char*>(rgb.data()), static_cast<std::streamsize>(rgb.size()));
      if (!in) throw InputError(label, "read error in the colour block");
      for (std::size_t i = 0; i < rgb.size(); ++i)
        ptm.colour[static_cast<std::size_t>(y) * h.width * 3 + i] = rgb[i] / 255.0f;
    }
  }
  return ptm;
}

// The JPEG header's lines after the biases: the compression parameter, then per plane
// its transform, motion vector x and y, decoding order, reference plane, compressed
// size and side-information size.
struct JpegLayout {
  std::vector<std::int64_t> transform, motion_x, motion_y, order, reference, size, side_size;
};

std::vector<std::int64_t> ReadIntegers(std::istream& in, int count, const std::string& what,
                                       const std::string& label, std::size_t& ln) {
  const std::string line = ReadHeaderLine(in, label, ++ln);
  const auto tokens = SplitWhitespace(line);
  if (static_cast<int>(tokens.size()) != count)
    throw InputError(label, "expected " + std::to_string(count) + " " + what, ln);
  std::vector<std::int64_t> values;
  for (const auto& token : tokens) values.push_back(ParseSigned(token, what, label, ln));
  return values;
}

JpegLayout ReadJpegLayout(std::istream& in, const PtmHeader& h, const std::string& label) {
  std::size_t ln = h.line;
  ReadIntegers(in, 1, "compression parameter", label, ln);
  const int n = h.NumPlanes();
  JpegLayout j;
  j.transform = ReadIntegers(in, n, "transforms", label, ln);
  j.motion_x = ReadIntegers(in, n, "motion vectors (x)", label, ln);
  j.motion_y = ReadIntegers(in, n, "motion vectors (y)", label, ln);
  j.order = ReadIntegers(in, n, "decoding orders", label, ln);
  j.reference = ReadIntegers(in, n, "reference planes", label, ln);
  j.size = ReadIntegers(in, n, "compressed sizes", label, ln);
  j.side_size = ReadIntegers(in, n, "side-information sizes", label, ln);
  std::vector<bool> rank_seen(static_cast<std::size_t>(n), false);
  for (int p = 0; p < n; ++p) {
    const auto k = static_cast<std::size_t>(p);
    const std::string plane = "plane " + std::to_string(p);
    if (j.transform[k] != 0 && j.transform[k] != 1)
      throw InputError(label, plane + ": transform " + std::to_string(j.transform[k]) +
                                  " (texlume reads none and plane inversion, 0 and 1)");
    if (j.motion_x[k] != 0 || j.motion_y[k] != 0)
      throw InputError(label, plane + ": motion-compensated prediction is not supported");
    if (j.order[k] < 0 || j.order[k] >= n || rank_seen[static_cast<std::size_t>(j.order[k])])
      throw InputError(label,
                       "the decoding orders are not a permutation of 0.." + std::to_string(n - 1));
    rank_seen[static_cast<std::size_t>(j.order[k])] = true;
    if (j.size[k] < 0 || j.side_size[k] < 0 || j.side_size[k] % 5 != 0)
      throw InputError(label,
                       plane + ": a negative size, or side information not in 5-byte records");
  }
  for (int p = 0; p < n; ++p) {
    const std::int64_t r = j.reference[static_cast<std::size_t>(p)];
    if (r != -1 && (r < 0 || r >= n ||
                    j.order[static_cast<std::size_t>(r)] >= j.order[static_cast<std::size_t>(p)]))
      throw InputError(label, "plane " + std::to_string(p) + " is predicted from plane " +
                                  std::to_string(r) + ", which is not decoded before it");
  }
  return j;
}

// PTM_FORMAT_JPEG_*: per plane a grey JPEG stream and its side information, in plane
// order. A plane predicted from a reference is the reference (inverted when its
// transform is 1) plus the decoded values minus 128; the side information then sets
// single bytes exactly (5-byte records: a big-endian texel offset and the value).
BytePlanes ReadJpegPlanes(std::istream& in, const PtmHeader& h, const std::string& label) {
  const JpegLayout j = ReadJpegLayout(in, h, label);
  const std::uint64_t available = BytesLeft(in);
  // Each size is bounded by the bytes left before any sum, so no sum can wrap.
  std::uint64_t total = 0;
  for (int p = 0; p < h.NumPlanes(); ++p) {
    const auto size = static_cast<std::uint64_t>(j.size[static_cast<std::size_t>(p)]);
    const auto side = static_cast<std::uint64_t>(j.side_size[static_cast<std::size_t>(p)]);
    if (size > available || side > available || (total += size + side) > available)
      throw InputError(label, "truncated payload: its JPEG streams need more than the " +
                                  std::to_string(available) + " bytes the file has left");
  }
  // The planes, the PTM's floats, the payload and one decoded plane.
  RequireMemory(
      static_cast<double>(h.Texels()) * (h.NumPlanes() * 5.0 + 1.0) + static_cast<double>(total),
      "reading the " + h.format_name + " PTM", label);
  std::string payload(total, '\0');
  in.read(payload.data(), static_cast<std::streamsize>(total));
  if (!in) throw InputError(label, "read error in the JPEG streams");
  const int n = h.NumPlanes();
  std::vector<std::string_view> stream(static_cast<std::size_t>(n)),
      side(static_cast<std::size_t>(n));
  std::size_t at = 0;
  for (std::size_t p = 0; p < static_cast<std::size_t>(n); ++p) {
    stream[p] = std::string_view(payload).substr(at, static_cast<std::size_t>(j.size[p]));
    at += static_cast<std::size_t>(j.size[p]);
    side[p] = std::string_view(payload).substr(at, static_cast<std::size_t>(j.side_size[p]));
    at += static_cast<std::size_t>(j.side_size[p]);
  }
  std::vector<int> by_rank(static_cast<std::size_t>(n));
  for (int p = 0; p < n; ++p)
    by_rank[static_cast<std::size_t>(j.order[static_cast<std::size_t>(p)])] = p;
  BytePlanes planes(static_cast<std::size_t>(n));
  for (const int p : by_rank) {
    const auto k = static_cast<std::size_t>(p);
    const cv::Mat decoded =
        DecodeGreyImageBytes(stream[k], "jpeg", h.width, h.height,
                             label + " (JPEG stream of plane " + std::to_string(p) + ")");
    planes[k].assign(decoded.data, decoded.data + h.Texels());
    if (j.reference[k] >= 0) {
      const std::vector<unsigned char>& ref = planes[static_cast<std::size_t>(j.reference[k])];
      const bool invert = j.transform[k] == 1;
      for (std::size_t t = 0; t < h.Texels(); ++t)
        planes[k][t] =
            static_cast<unsigned char>(planes[k][t] + (invert ? 255 - ref[t] : ref[t]) - 128);
    }
    for (std::size_t r = 0; r + 5 <= side[k].size(); r += 5) {
      const auto byte = [&](std::size_t i) {
        return static_cast<std::uint64_t>(static_cast<unsigned char>(side[k][r + i]));
      };
      const std::uint64_t offset = byte(0) << 24 | byte(1) << 16 | byte(2) << 8 | byte(3);
      if (offset >= h.Texels())
        throw InputError(label, "plane " + std::to_string(p) + "'s side information names texel " +
                                    std::to_string(offset) + " of " + std::to_string(h.Texels()));
      planes[k][offset] = static_cast<unsigned char>(side[k][r + 4]);
    }
  }
  return planes;
}

// Coefficient = (byte - bias) * scale / 255 (display values in [0, 1]); colour byte / 255.
// The file's rows run from the bottom up.
Ptm PtmFromPlanes(const PtmHeader& h, const BytePlanes& planes) {
  Ptm ptm;
  ptm.Resize(h.format, h.width, h.height);
  for (int y = 0; y < h.height; ++y) {
    const std::size_t file_row = static_cast<std::size_t>(h.height - 1 - y) * h.width;
    for (int x = 0; x < h.width; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * h.width + x;
      for (int q = 0; q < ptm.NumPolynomials(); ++q) {
        float* a = ptm.Coefficients(t, q);
        for (int i = 0; i < 6; ++i)
          a[i] = (static_cast<float>(planes[static_cast<std::size_t>(q * 6 + i)][file_row + x]) -
                  h.bias[i]) *
                 h.scale[i] / 255.0f;
      }
      if (h.format == PtmFormat::kLrgb)
        for (int c = 0; c < 3; ++c)
          ptm.colour[t * 3 + static_cast<std::size_t>(c)] =
              planes[static_cast<std::size_t>(6 + c)][file_row + x] / 255.0f;
    }
  }
  return ptm;
}

// A .ptm's body after the header: `planes` planes one after another, each of rows
// height - 1 down to 0 (a .ptm's order) of `row_bytes` made by encode_row(y, plane,
// bytes), which must not throw (the stream may). Blocks of rows are written by one
// task while tasks of a row each encode the next block. With at_once 1 the planes
// are written one after another, in order (any stream). With at_once > 1 (a file,
// which can be sought and written beyond its end) that many planes are encoded
// together, reading the texels once, and each block is written at its plane's place.
template <typename EncodeRow>
void WritePlanesBottomUp(std::ostream& out, int height, std::size_t row_bytes, int planes,
                         int at_once, const EncodeRow& encode_row) {
  constexpr int kBlockRows = 64;
  const std::streamoff body = out.tellp();
  if (body < 0) at_once = 1;  // a stream that cannot tell its place: one plane after another
  const bool positioned = at_once > 1;
  const auto plane_bytes = static_cast<std::streamoff>(row_bytes) * height;
  const int blocks = (height + kBlockRows - 1) / kBlockRows;
  const std::size_t block_bytes = row_bytes * kBlockRows;
  std::vector<char> block[2];
  for (auto& bytes : block) bytes.resize(block_bytes * static_cast<std::size_t>(at_once));
  const auto rows_of = [&](int b) { return std::min(kBlockRows, height - b * kBlockRows); };
  FirstException error;
  for (int first = 0; first < planes && !error.Failed(); first += at_once) {
#pragma omp parallel
#pragma omp single
    for (int b = 0; b <= blocks; ++b) {
      for (int p = 0; p < at_once && b < blocks; ++p) {
        char* bytes = block[b % 2].data() + static_cast<std::size_t>(p) * block_bytes;
        const int top = height - 1 - b * kBlockRows;
        for (int r = 0; r < rows_of(b); ++r) {
#pragma omp task firstprivate(r, top, bytes, p) shared(encode_row, first)
          encode_row(top - r, first + p, bytes + static_cast<std::size_t>(r) * row_bytes);
        }
      }
      if (b > 0) {
        const char* bytes = block[(b - 1) % 2].data();
        const auto offset = static_cast<std::streamoff>(block_bytes) * (b - 1);
        const auto size =
            static_cast<std::streamsize>(static_cast<std::size_t>(rows_of(b - 1)) * row_bytes);
#pragma omp task firstprivate(bytes, offset, size) shared(out, first, error)
        error.Run([&] {  // a stream that throws: rethrown below, once the tasks are done
          for (int p = 0; p < at_once; ++p) {
            if (positioned) out.seekp(body + plane_bytes * (first + p) + offset);
            out.write(bytes + static_cast<std::size_t>(p) * block_bytes, size);
          }
        });
      }
#pragma omp taskwait
      if (error.Failed()) break;
    }
  }
  error.Rethrow();
  if (positioned) out.seekp(body + plane_bytes * planes);
}

// The header, then the planes: `at_once` as in WritePlanesBottomUp.
void WritePtm(const Ptm& ptm, std::ostream& out, int at_once) {
  const auto q = Quantisers(ptm);
  const GroupEncoder encoder(q);
  out << "PTM_1.2\n"
      << (ptm.format == PtmFormat::kLrgb ? "PTM_FORMAT_LRGB" : "PTM_FORMAT_RGB") << "\n"
      << ptm.width << "\n"
      << ptm.height << "\n";
  out << std::setprecision(9);
  for (int i = 0; i < 6; ++i) out << (i ? " " : "") << q[static_cast<std::size_t>(i)].scale;
  out << "\n";
  for (int i = 0; i < 6; ++i) out << (i ? " " : "") << q[static_cast<std::size_t>(i)].bias;
  out << "\n";
  const auto width = static_cast<std::size_t>(ptm.width);
  const int polynomials = ptm.NumPolynomials();
  WritePlanesBottomUp(out, ptm.height, width * 6, polynomials, std::min(at_once, polynomials),
                      [&](int y, int p, char* row) {
                        encoder.Encode(ptm.Coefficients(static_cast<std::size_t>(y) * width, p),
                                       static_cast<std::size_t>(polynomials) * 6, width,
                                       reinterpret_cast<std::uint8_t*>(row));
                      });
  if (ptm.format == PtmFormat::kLrgb) {
    WritePlanesBottomUp(out, ptm.height, width * 3, 1, 1, [&](int y, int, char* row) {
      const float* colour = &ptm.colour[static_cast<std::size_t>(y) * width * 3];
      for (std::size_t i = 0; i < width * 3; ++i)
        row[i] = static_cast<char>(RoundToByte(255.0f * colour[i]));
    });
  }
}

}  // namespace

void WritePtm(const Ptm& ptm, std::ostream& out) { WritePtm(ptm, out, 1); }

void WritePtmFile(const Ptm& ptm, const std::filesystem::path& path) {
  WriteFileAtomically(
      path, [&](std::ostream& out) { WritePtm(ptm, out, 3); }, true);
}

Ptm ReadPtm(std::istream& in, const std::string& label) {
  const PtmHeader header = ReadPtmHeader(in, label);
  if (!header.jpeg) return ReadRawPtm(in, header, label);
  return PtmFromPlanes(header, ReadJpegPlanes(in, header, label));
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

WebPlanes QuantisePlanes(const std::vector<std::vector<float>>& planes, int width, int height) {
  WebPlanes web;
  web.width = width;
  web.height = height;
  for (const auto& p : planes) {
    const auto [lo_it, hi_it] = std::minmax_element(p.begin(), p.end());
    const float lo = *lo_it, hi = *hi_it;
    web.scales.push_back(hi > lo ? hi - lo : 1.0f);
    web.biases.push_back(-lo / web.scales.back());
  }
  for (std::size_t j = 0; j * 3 < planes.size(); ++j) {
    cv::Mat& image = web.images.emplace_back(height, width, CV_8UC3, cv::Scalar::all(0));
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * width + x;
        cv::Vec3b& px = image.at<cv::Vec3b>(y, x);
        for (std::size_t c = 0; c < 3 && j * 3 + c < planes.size(); ++c) {
          const std::size_t k = j * 3 + c;
          const float v = (planes[k][t] / web.scales[k] + web.biases[k]) * 255.0f;
          px[2 - c] = static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));  // BGR
        }
      }
    }
  }
  return web;
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
  WebPlanes web = QuantisePlanes(planes, ptm.width, ptm.height);
  web.colorspace = ptm.format == PtmFormat::kLrgb ? "lrgb" : "rgb";
  return web;
}

int WriteWebPlanes(const WebPlanes& web, const std::filesystem::path& dir, int jpeg_quality) {
  std::filesystem::create_directories(dir);
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
  nlohmann::json info = web.Info();
  info["format"] = "jpg";
  info["quality"] = jpeg_quality;
  WriteFileAtomically(
      dir / "info.json", [&](std::ostream& out) { out << info.dump(2) << "\n"; }, false);
  return static_cast<int>(web.images.size()) + 1;
}

nlohmann::json WebPlanes::Info() const {
  return {{"width", width},
          {"height", height},
          {"type", type},
          {"colorspace", colorspace},
          {"nplanes", scales.size()},
          {"materials", nlohmann::json::array({{{"scale", scales}, {"bias", biases}}})}};
}

int WriteRelightWeb(const Ptm& ptm, const std::filesystem::path& dir, int jpeg_quality) {
  // Always RGB: OpenLIME (1.2.6 and before) draws an "lrgb" PTM with its luminance as
  // the pixel's alpha (LRGB.render returns l * vec4(basecolor, 1)), so every texel whose
  // luminance is under 1 comes out partly transparent and dark (docs/ptm_format.md).
  return WriteWebPlanes(QuantiseWebPlanes(AsRgb(ptm)), dir, jpeg_quality);
}

Ptm ReadPtmAnyFormat(const std::filesystem::path& path) {
  return LowerCaseExtension(path) == ".exr" ? ReadPtmExr(path) : ReadPtmFile(path);
}

}  // namespace texlume::ptm
