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
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "ptm/exr_io.h"

namespace texlume::ptm {
namespace {

// Plausibility bounds of a .ptm file's quantisation (docs/ptm_format.md): a
// coefficient (byte - bias) * scale / 255 of a relit value in [0, 1] never needs
// more; beyond them a file relights to garbage.
constexpr double kMaxPtmScale = 1e6;  // the message below says 1e6
constexpr std::int64_t kMaxPtmBias = 1000000;

// x rounded half away from zero (as std::lround) and clamped to 0..255; NaN is 0.
// Exact in float: the fraction x - trunc(x) of a float in [0, 255] needs no
// rounding (Sterbenz), and branch-free so that the encoding loops vectorise.
inline std::uint8_t RoundToByte(float x) {
  const float clamped = std::min(x > 0.0f ? x : 0.0f, 255.0f);
  const int whole = static_cast<int>(clamped);
  return static_cast<std::uint8_t>(whole + (clamped - static_cast<float>(whole) >= 0.5f ? 1 : 0));
}

// Quantisation of one coefficient index: coefficient = (byte - bias) * scale.
struct Quantiser {
  float scale = 1.0f;
  int bias = 0;
  std::uint8_t Encode(float v) const { return RoundToByte(v / scale + static_cast<float>(bias)); }
};

// A float's bits as an unsigned key in the float's order (IEEE 754: the sign bit
// flipped for a positive value, every bit for a negative one).
std::uint32_t OrderedKey(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  // Every bit flipped for a negative value, the sign bit for a positive one (C++20:
  // >> of a signed value is arithmetic); branch-free so that key loops vectorise.
  return bits ^ (static_cast<std::uint32_t>(static_cast<std::int32_t>(bits) >> 31) | 0x80000000u);
}

// The float whose OrderedKey is `key`.
float FromOrderedKey(std::uint32_t key) {
  const std::uint32_t bits = (key & 0x80000000u) ? (key & 0x7fffffffu) : ~key;
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// The values 255 a_i of each coefficient index i over every texel and polynomial
// (a: 6 floats per texel and polynomial), and of each the values of two ranks,
// found exactly in two passes over the coefficients without a copy of them (a
// radix select): a histogram of the keys' high 16 bits finds each rank's bin,
// then a histogram of the low 16 bits of the keys in that bin finds the key.
class CoefficientRanks {
 public:
  static constexpr std::size_t kBins = std::size_t{1} << 16;

  CoefficientRanks(const float* a, std::size_t values, std::array<std::size_t, 2> ranks)
      : a_(a), ranks_(ranks), count_(values / 6) {}

  // The value of rank ranks[r] among index i's values, for every i and r.
  std::array<std::array<float, 2>, 6> Values() {
    const std::vector<std::size_t> high = Count(false);
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t r = 0; r < 2; ++r) high_[i][r] = Find(high, i * 2, ranks_[r], below_[i][r]);
    const std::vector<std::size_t> low = Count(true);
    std::array<std::array<float, 2>, 6> values;
    for (std::size_t i = 0; i < 6; ++i) {
      for (std::size_t r = 0; r < 2; ++r) {
        std::size_t below = below_[i][r];
        const std::uint32_t digit = Find(low, i * 2 + r, ranks_[r], below);
        values[i][r] = FromOrderedKey(high_[i][r] << 16 | digit);
      }
    }
    return values;
  }

 private:
  std::uint32_t Key(std::size_t j, std::size_t i) const {
    return OrderedKey(255.0f * a_[j * 6 + i]);
  }

  // Histogram h = i * 2 + r of the keys' high digits (r = 0: one per index), or of
  // the low digits of the keys whose high digit is high_[i][r].
  std::vector<std::size_t> Count(bool low_digits) const {
    std::vector<std::size_t> bins(12 * kBins, 0);
#pragma omp parallel
    {
      std::vector<std::uint32_t> local(12 * kBins, 0);  // < 2^32 values per thread
#pragma omp for schedule(static) nowait
      for (std::size_t j = 0; j < count_; ++j) {
        for (std::size_t i = 0; i < 6; ++i) {
          const std::uint32_t key = Key(j, i);
          if (!low_digits) {
            ++local[i * 2 * kBins + (key >> 16)];
            continue;
          }
          for (std::size_t r = 0; r < 2; ++r)
            if ((key >> 16) == high_[i][r]) ++local[(i * 2 + r) * kBins + (key & 0xffffu)];
        }
      }
#pragma omp critical
      for (std::size_t b = 0; b < bins.size(); ++b) bins[b] += local[b];
    }
    return bins;
  }

  // The digit whose bin in histogram h holds rank `rank`; `below` (values before
  // the histogram's first bin) becomes the values before that digit's bin.
  static std::uint32_t Find(const std::vector<std::size_t>& bins, std::size_t h, std::size_t rank,
                            std::size_t& below) {
    std::uint32_t digit = 0;
    while (below + bins[h * kBins + digit] <= rank) below += bins[h * kBins + digit++];
    return digit;
  }

  const float* a_;  // 6 per texel and polynomial
  std::array<std::size_t, 2> ranks_;
  std::size_t count_;
  std::array<std::array<std::uint32_t, 2>, 6> high_{};
  std::array<std::array<std::size_t, 2>, 6> below_{};
};

// CoefficientRanks' values in one pass over the coefficients, when a strided
// sample brackets each rank: every step-th texel's keys give, per index and rank,
// a key range holding the rank with a margin of 8 standard deviations of a sample
// quantile's rank; the pass counts the keys below each range and collects those
// inside it, among which the rank's key is selected. Exact like CoefficientRanks;
// Values() returns false (and the caller falls back to it) when a rank falls
// outside its range or a range holds too many keys (many equal values).
class BracketedRanks {
 public:
  BracketedRanks(const float* a, std::size_t values, std::array<std::size_t, 2> ranks)
      : a_(a), ranks_(ranks), count_(values / 6) {}

  bool Values(std::array<std::array<float, 2>, 6>& values) {
    const std::size_t step = std::max<std::size_t>(1, count_ / kSampleTarget);
    std::array<std::vector<std::uint32_t>, 6> samples;
    for (auto& sample : samples) sample.reserve((count_ + step - 1) / step);
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t i = 0; i < 6; ++i) Bracket(i, step, samples[i]);
    limit_ = *std::max_element(limits_.begin(), limits_.end());
    if (!CountAndCollect()) return false;
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t r = 0; r < 2; ++r) {
        std::vector<std::uint32_t>& inside = inside_[i][r];
        if (ranks_[r] < below_[i][r] || ranks_[r] - below_[i][r] >= inside.size()) return false;
        const auto nth = inside.begin() + static_cast<std::ptrdiff_t>(ranks_[r] - below_[i][r]);
        std::nth_element(inside.begin(), nth, inside.end());
        values[i][r] = FromOrderedKey(*nth);
      }
    return true;
  }

 private:
  static constexpr std::size_t kSampleTarget = std::size_t{1} << 18;

  std::uint32_t Key(std::size_t j, std::size_t i) const {
    return OrderedKey(255.0f * a_[j * 6 + i]);
  }

  // Index i's key range around each rank, from every step-th texel's keys, in
  // `sample` (its memory reserved by the caller: no allocation on the threads).
  void Bracket(std::size_t i, std::size_t step, std::vector<std::uint32_t>& sample) {
    for (std::size_t j = 0; j < count_; j += step) sample.push_back(Key(j, i));
    const double m = static_cast<double>(sample.size());
    for (std::size_t r = 0; r < 2; ++r) {
      const double p = static_cast<double>(ranks_[r]) / static_cast<double>(count_);
      const double at = p * m, margin = 8.0 * std::sqrt(m * p * (1.0 - p)) + 16.0;
      const auto nth = [&](double rank, std::uint32_t beyond) {
        if (rank < 0.0 || rank > m - 1.0) return beyond;
        const auto it = sample.begin() + static_cast<std::ptrdiff_t>(rank);
        std::nth_element(sample.begin(), it, sample.end());
        return *it;
      };
      low_[i][r] = nth(std::floor(at - margin), 0u);
      high_[i][r] = nth(std::ceil(at + margin), std::numeric_limits<std::uint32_t>::max());
      // At most 4 times the keys a range of this width should hold, and 2^16.
      limits_[i] = std::max<std::size_t>(
          limits_[i], static_cast<std::size_t>(4.0 * 2.0 * margin * static_cast<double>(step)) +
                          (std::size_t{1} << 16));
    }
  }

  // Counts each index's keys below its ranges and collects those inside; false
  // when a range holds more than limit_ keys. Two texels at a time, in fixed-length
  // loops over their keys that the compiler vectorises; a pair with a key inside a
  // range, rare, is collected one key at a time.
  bool CountAndCollect() {
    for (std::size_t e = 0; e < kPair; ++e)
      for (std::size_t r = 0; r < 2; ++r) {
        low_of_lane_[r][e] = low_[e % 6][r];
        width_of_lane_[r][e] = high_[e % 6][r] - low_[e % 6][r];
      }
    bool overflow = false;
    std::exception_ptr error;  // from a thread's allocation: rethrown, not terminate()
    const std::size_t blocks = (count_ + kBlock - 1) / kBlock;
#pragma omp parallel
    {
      Counts counts;
#pragma omp for schedule(static) nowait
      for (std::size_t b = 0; b < blocks; ++b) {
        try {
          CountBlock(b * kBlock, std::min(count_, (b + 1) * kBlock), counts);
        } catch (...) {
#pragma omp critical
          error = std::current_exception();
        }
      }
#pragma omp critical
      for (std::size_t i = 0; i < 6; ++i)
        for (std::size_t r = 0; r < 2; ++r) {
          below_[i][r] += counts.below[i][r];
          overflow = overflow || counts.inside[i][r].size() >= limit_;
          inside_[i][r].insert(inside_[i][r].end(), counts.inside[i][r].begin(),
                               counts.inside[i][r].end());
        }
    }
    if (error) std::rethrow_exception(error);
    return !overflow;
  }

  struct Counts {
    std::array<std::array<std::size_t, 2>, 6> below{};
    std::array<std::array<std::vector<std::uint32_t>, 2>, 6> inside;
  };

  // Texels [begin, end): a pair at a time, the last odd one on its own. A key is
  // inside its range when key - low <= high - low (unsigned: a key below wraps).
  void CountBlock(std::size_t begin, std::size_t end, Counts& counts) const {
    std::uint32_t below[2][kPair] = {};
    std::size_t j = begin;
    for (; j + 2 <= end; j += 2) {
      std::uint32_t key[kPair];
      for (std::size_t e = 0; e < kPair; ++e) key[e] = OrderedKey(255.0f * a_[j * 6 + e]);
      std::uint32_t inside[kPair];
      for (std::size_t e = 0; e < kPair; ++e) {
        below[0][e] += key[e] < low_of_lane_[0][e] ? 1u : 0u;
        below[1][e] += key[e] < low_of_lane_[1][e] ? 1u : 0u;
        inside[e] = (key[e] - low_of_lane_[0][e] <= width_of_lane_[0][e] ? 1u : 0u) |
                    (key[e] - low_of_lane_[1][e] <= width_of_lane_[1][e] ? 1u : 0u);
      }
      std::uint32_t any = 0;
      for (std::size_t e = 0; e < kPair; ++e) any |= inside[e];
      if (any) [[unlikely]]
        for (std::size_t t = j; t < j + 2; ++t) Collect(t, counts, nullptr);
    }
    for (std::size_t r = 0; r < 2; ++r)
      for (std::size_t e = 0; e < kPair; ++e) counts.below[e % 6][r] += below[r][e];
    if (j < end) Collect(j, counts, &counts.below);
  }

  // Texel j's keys inside their ranges into `counts`, and those below into `below`
  // when given.
  void Collect(std::size_t j, Counts& counts,
               std::array<std::array<std::size_t, 2>, 6>* below) const {
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t r = 0; r < 2; ++r) {
        const std::uint32_t key = Key(j, i);
        if (below && key < low_[i][r]) ++(*below)[i][r];
        std::vector<std::uint32_t>& inside = counts.inside[i][r];
        if (key >= low_[i][r] && key <= high_[i][r] && inside.size() < limit_)
          inside.push_back(key);
      }
  }

  static constexpr std::size_t kPair = 12;      // two texels' coefficients
  static constexpr std::size_t kBlock = 65536;  // texels counted in 32-bit lanes at once

  const float* a_;  // 6 per texel and polynomial
  std::array<std::size_t, 2> ranks_;
  std::size_t count_;
  std::size_t limit_ = 0;
  std::array<std::size_t, 6> limits_{};  // limit_ of each index
  std::array<std::array<std::uint32_t, 2>, 6> low_{}, high_{};
  // Each lane's range of a pair of texels: its low key and its width.
  std::uint32_t low_of_lane_[2][kPair] = {}, width_of_lane_[2][kPair] = {};
  std::array<std::array<std::size_t, 2>, 6> below_{};
  std::array<std::array<std::vector<std::uint32_t>, 2>, 6> inside_;
};

// Quantisers per coefficient index, over every texel (and channel for RGB), in
// 0-255 units: the range between the 0.1 % and 99.9 % quantiles, widened to hold 0,
// in 255 steps.
std::array<Quantiser, 6> Quantisers(const Ptm& ptm) {
  std::array<Quantiser, 6> q;
  const std::size_t count = ptm.coefficients.size() / 6;
  if (count == 0) return q;
  const std::array<std::size_t, 2> ranks{count / 1000, count - 1 - count / 1000};
  std::array<std::array<float, 2>, 6> values;
  const float* a = ptm.coefficients.data();
  if (!BracketedRanks(a, ptm.coefficients.size(), ranks).Values(values))
    values = CoefficientRanks(a, ptm.coefficients.size(), ranks).Values();
  for (std::size_t i = 0; i < 6; ++i) {
    const float lo = std::min(0.0f, values[i][0]);
    const float hi = std::max(0.0f, values[i][1]);
    q[i].scale = hi > lo ? (hi - lo) / 255.0f : 1.0f;
    q[i].bias = static_cast<int>(std::lround(-lo / q[i].scale));
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

}  // namespace

namespace {

// Encodes groups of a polynomial's 6 coefficients (display values) as a .ptm's bytes,
// four groups at a time in fixed-length loops that the compiler vectorises: the
// same bytes as Quantiser::Encode.
class GroupEncoder {
 public:
  explicit GroupEncoder(const std::array<Quantiser, 6>& q) {
    for (std::size_t j = 0; j < kValues; ++j) {
      scale_[j] = q[j % 6].scale;
      bias_[j] = static_cast<float>(q[j % 6].bias);
    }
  }

  // The groups a[t * stride, t * stride + 6) for t < count, into out[t * 6 + i].
  void Encode(const float* a, std::size_t stride, std::size_t count, std::uint8_t* out) const {
    for (std::size_t t = 0; t < count; t += kGroups) {
      const std::size_t n = std::min(kGroups, count - t);
      float v[kValues];
      for (std::size_t g = 0; g < kGroups; ++g)
        std::memcpy(v + g * 6, a + (t + std::min(g, n - 1)) * stride, 6 * sizeof(float));
      std::int32_t byte[kValues];
      for (std::size_t j = 0; j < kValues; ++j) {  // RoundToByte, lane by lane
        const float x = 255.0f * v[j] / scale_[j] + bias_[j];
        const float clamped = std::min(x > 0.0f ? x : 0.0f, 255.0f);
        const auto whole = static_cast<std::int32_t>(clamped);
        byte[j] = whole + (clamped - static_cast<float>(whole) >= 0.5f ? 1 : 0);
      }
      std::uint8_t bytes[kValues];
      for (std::size_t j = 0; j < kValues; ++j) bytes[j] = static_cast<std::uint8_t>(byte[j]);
      std::memcpy(out + t * 6, bytes, n * 6);
    }
  }

 private:
  static constexpr std::size_t kGroups = 4, kValues = kGroups * 6;
  float scale_[kValues], bias_[kValues];
};

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
  std::exception_ptr error;
  for (int first = 0; first < planes && !error; first += at_once) {
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
        try {
          for (int p = 0; p < at_once; ++p) {
            if (positioned) out.seekp(body + plane_bytes * (first + p) + offset);
            out.write(bytes + static_cast<std::size_t>(p) * block_bytes, size);
          }
        } catch (...) {  // a stream that throws: rethrown below, once the tasks are done
          error = std::current_exception();
        }
      }
#pragma omp taskwait
      if (error) break;
    }
  }
  if (error) std::rethrow_exception(error);
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
