#include "ptm/ptm_io.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <streambuf>

#include "core/errors.h"
#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

Ptm RandomPtm(PtmFormat format, int width, int height, std::uint32_t seed) {
  Ptm ptm;
  ptm.Resize(format, width, height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.3f, 0.3f);
  for (float& a : ptm.coefficients) a = u(rng);
  for (std::size_t t = 0; t < ptm.NumTexels(); ++t) {
    for (int p = 0; p < ptm.NumPolynomials(); ++p) ptm.Coefficients(t, p)[5] += 0.5f;
  }
  std::uniform_real_distribution<float> c(0.2f, 1.0f);
  for (float& v : ptm.colour) v = c(rng);
  return ptm;
}

class PtmFileTest : public ::testing::TestWithParam<PtmFormat> {};

TEST_P(PtmFileTest, RoundTripErrorIsBoundedByTheQuantisationStep) {
  const Ptm ptm = RandomPtm(GetParam(), 37, 23, 1);
  std::stringstream s;
  WritePtm(ptm, s);
  const Ptm back = ReadPtm(s, "mem.ptm");
  ASSERT_EQ(back.width, 37);
  ASSERT_EQ(back.height, 23);
  ASSERT_EQ(back.format, ptm.format);
  // 8 bits over each coefficient's range (at most 0.8 wide here, 0 included):
  // within half a step, but for the 0.1 % tails clamped to the robust range.
  std::size_t within = 0;
  for (std::size_t i = 0; i < ptm.coefficients.size(); ++i) {
    const double error = std::abs(back.coefficients[i] - ptm.coefficients[i]);
    within += error <= 0.8 / 255.0 / 2 + 1e-6 ? 1 : 0;
    ASSERT_LT(error, 0.02) << i;
  }
  EXPECT_GE(within, ptm.coefficients.size() * 995 / 1000);
  for (std::size_t i = 0; i < ptm.colour.size(); ++i) {
    ASSERT_NEAR(back.colour[i], ptm.colour[i], 0.5 / 255 + 1e-6);
  }
}

TEST_P(PtmFileTest, ByteLayoutMatchesTheHpSpecification) {
  // An independent reading of the layout (DESIGN.md): header lines, then per
  // block rows bottom to top, 6 bytes per texel; LRGB then RGB bytes.
  Ptm ptm = RandomPtm(GetParam(), 3, 2, 2);
  std::stringstream s;
  WritePtm(ptm, s);
  const std::string bytes = s.str();
  std::istringstream header(bytes);
  std::string version, format, w, h, scales_line, biases_line;
  std::getline(header, version);
  std::getline(header, format);
  std::getline(header, w);
  std::getline(header, h);
  std::getline(header, scales_line);
  std::getline(header, biases_line);
  EXPECT_EQ(version, "PTM_1.2");
  EXPECT_EQ(format, GetParam() == PtmFormat::kLrgb ? "PTM_FORMAT_LRGB" : "PTM_FORMAT_RGB");
  EXPECT_EQ(w, "3");
  EXPECT_EQ(h, "2");
  std::istringstream sl(scales_line), bl(biases_line);
  double scale[6];
  int bias[6];
  for (int i = 0; i < 6; ++i) sl >> scale[i], bl >> bias[i];
  const std::size_t payload = static_cast<std::size_t>(header.tellg());
  const int polys = ptm.NumPolynomials();
  ASSERT_EQ(bytes.size() - payload,
            static_cast<std::size_t>(3 * 2 * (polys * 6 + (polys == 1 ? 3 : 0))));
  for (int p = 0; p < polys; ++p) {
    for (int file_row = 0; file_row < 2; ++file_row) {
      const int y = 1 - file_row;  // bottom row first
      for (int x = 0; x < 3; ++x) {
        for (int i = 0; i < 6; ++i) {
          const auto byte = static_cast<unsigned char>(
              bytes[payload + static_cast<std::size_t>(((p * 2 + file_row) * 3 + x) * 6 + i)]);
          const double value = (byte - bias[i]) * scale[i] / 255.0;
          EXPECT_NEAR(value, ptm.Coefficients(static_cast<std::size_t>(y * 3 + x), p)[i],
                      scale[i] / 255.0);
        }
      }
    }
  }
  if (GetParam() == PtmFormat::kLrgb) {
    const std::size_t rgb = payload + 3 * 2 * 6;
    EXPECT_EQ(static_cast<unsigned char>(bytes[rgb]),
              std::lround(255 * ptm.colour[3 * 3]));  // (0, 1)
  }
}

// The header's ranges against the known answer by selection: [min(0, v_(n/1000)),
// max(0, v_(n-1-n/1000))] of the values 255 a_i over every texel and polynomial, n of
// them, in 255 steps.
void ExpectExactRanges(const Ptm& ptm) {
  std::stringstream s;
  WritePtm(ptm, s);
  std::string line;
  for (int l = 0; l < 4; ++l) std::getline(s, line);
  double scale[6];
  int bias[6];
  for (double& v : scale) s >> v;
  for (int& v : bias) s >> v;
  for (int i = 0; i < 6; ++i) {
    std::vector<float> values;
    for (std::size_t t = 0; t < ptm.NumTexels(); ++t)
      for (int p = 0; p < ptm.NumPolynomials(); ++p)
        values.push_back(255.0f * ptm.Coefficients(t, p)[i]);
    const std::size_t n = values.size();
    std::nth_element(values.begin(), values.begin() + n / 1000, values.end());
    const float lo = std::min(0.0f, values[n / 1000]);
    std::nth_element(values.begin(), values.begin() + (n - 1 - n / 1000), values.end());
    const float hi = std::max(0.0f, values[n - 1 - n / 1000]);
    EXPECT_FLOAT_EQ(static_cast<float>(scale[i]), (hi - lo) / 255.0f) << "coefficient " << i;
    EXPECT_EQ(bias[i], std::lround(-lo / ((hi - lo) / 255.0f))) << "coefficient " << i;
  }
}

TEST_P(PtmFileTest, EachCoefficientsRangeLeavesOutItsLowestAndHighestThousandth) {
  Ptm ptm = RandomPtm(GetParam(), 211, 97, 4);
  std::mt19937 rng(5);
  std::normal_distribution<float> spread(0.0f, 1.0f);
  for (float& a : ptm.coefficients) a = a * spread(rng) * spread(rng);  // long tails, ties
  for (std::size_t t = 0; t < ptm.NumTexels(); t += 3) ptm.Coefficients(t)[2] = 0.125f;
  ExpectExactRanges(ptm);
}

// On more than 2^19 values per coefficient the ranges are found from a strided
// sample and one pass (ptm_quantise.cpp, BracketedRanks); with most of one coefficient's
// values equal, by the two-pass radix select. Both exact.
TEST(PtmFile, LargePtmRangesAreExactFromTheSampleAndTheFallback) {
  Ptm ptm = RandomPtm(PtmFormat::kLrgb, 2200, 1000, 6);
  std::mt19937 rng(8);
  std::normal_distribution<float> spread(0.0f, 1.0f);
  for (float& a : ptm.coefficients) a = a * spread(rng) * spread(rng);  // long tails
  ExpectExactRanges(ptm);
  for (std::size_t t = 0; t < ptm.NumTexels(); ++t)
    if (t % 50 != 0) ptm.Coefficients(t)[4] = -0.25f;  // index 4: a range of ties
  ExpectExactRanges(ptm);
}

// A stream that can only be appended to, as a pipe: it cannot tell or seek its place.
class AppendOnlyBuffer : public std::streambuf {
 public:
  std::string bytes;

 protected:
  int_type overflow(int_type c) override {
    if (c != traits_type::eof()) bytes.push_back(static_cast<char>(c));
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    bytes.append(s, static_cast<std::size_t>(n));
    return n;
  }
};

// A file is written by blocks of 64 rows, every polynomial's plane at its place in
// one pass over the texels; a stream plane after plane: the same bytes, also on a
// stream that cannot seek.
TEST_P(PtmFileTest, AFileHoldsTheBytesAStreamDoes) {
  testing::TempDir tmp;
  for (const int height : {1, 64, 150}) {
    const Ptm ptm = RandomPtm(GetParam(), 37, height, 9);
    std::stringstream s;
    WritePtm(ptm, s);
    AppendOnlyBuffer pipe;
    std::ostream piped(&pipe);
    WritePtm(ptm, piped);
    WritePtmFile(ptm, tmp / "file.ptm");
    std::ifstream in(tmp / "file.ptm", std::ios::binary);
    const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(file.size(), s.str().size()) << "height " << height;
    EXPECT_TRUE(file == s.str()) << "height " << height;
    EXPECT_TRUE(piped.good());
    EXPECT_TRUE(pipe.bytes == s.str()) << "height " << height;
  }
}

INSTANTIATE_TEST_SUITE_P(Formats, PtmFileTest,
                         ::testing::Values(PtmFormat::kLrgb, PtmFormat::kRgb));

TEST(PtmFile, CorruptHeadersAndTruncatedPayloadsAreCleanErrors) {
  std::stringstream good;
  WritePtm(RandomPtm(PtmFormat::kLrgb, 4, 4, 3), good);
  const std::string bytes = good.str();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "truncated header"},
      {"PTM_9.9\n", "not a PTM file"},
      {"PTM_1.2\nPTM_FORMAT_JPEGLS_LRGB\n", "unsupported PTM format"},
      {"PTM_1.2\nPTM_FORMAT_RGB\n0\n4\n", "implausible size"},
      {"PTM_1.2\nPTM_FORMAT_RGB\n4\n4\n1 2 3\n", "expected 6 scales"},
      {"PTM_1.2\nPTM_FORMAT_RGB\n4\n4\n1 1 1 1 1 1\n0 0 0 x 0 0\n", "integer"},
      {"PTM_1.2\nPTM_FORMAT_RGB\n60000\n60000\n1 1 1 1 1 1\n0 0 0 0 0 0\n", "truncated payload"},
      {bytes.substr(0, bytes.size() - 1), "truncated payload"}};
  for (const auto& [text, expected] : cases) {
    std::istringstream in(text);
    const std::string error = testing::InputErrorMessage([&] { ReadPtm(in, "x.ptm"); });
    EXPECT_EQ(error.rfind("x.ptm", 0), 0u) << error;
    EXPECT_NE(error.find(expected), std::string::npos)
        << "'" << text.substr(0, 30) << "' gave " << error;
  }
}

// A PTM_FORMAT_JPEG_LRGB file as HP's format lays it out: one grey JPEG stream per
// plane, planes predicted from others (one inverted), side information that sets
// bytes exactly, and a decoding order that is not the plane order.
struct JpegPtmFile {
  std::string bytes;
  std::vector<std::vector<unsigned char>> planes;  // what each plane decodes to, file row order
};

JpegPtmFile MakeJpegLrgb(int w, int h) {
  JpegPtmFile f;
  const int n = 9;
  for (int p = 0; p < n; ++p) {
    std::vector<unsigned char> plane(static_cast<std::size_t>(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)  // smooth, so a quality-100 JPEG is within a level or two
        plane[static_cast<std::size_t>(y) * w + x] =
            static_cast<unsigned char>(40 + 20 * p + 2 * x + y);
    f.planes.push_back(plane);
  }
  // Plane 1 is predicted from plane 0, plane 2 from plane 0 inverted.
  const std::vector<int> reference = {-1, 0, 0, -1, -1, -1, -1, -1, -1};
  const std::vector<int> transform = {0, 0, 1, 0, 0, 0, 0, 0, 0};
  const std::vector<int> order = {2, 3, 4, 0, 1, 5, 6, 7, 8};
  std::string streams;
  std::vector<std::size_t> sizes, side_sizes;
  for (int p = 0; p < n; ++p) {
    cv::Mat stored(h, w, CV_8UC1);
    for (std::size_t t = 0; t < f.planes[0].size(); ++t) {
      int v = f.planes[static_cast<std::size_t>(p)][t];
      if (reference[static_cast<std::size_t>(p)] >= 0) {
        const int r = f.planes[0][t];
        v = v - (transform[static_cast<std::size_t>(p)] ? 255 - r : r) + 128;
      }
      stored.data[t] = static_cast<unsigned char>(v);
    }
    std::vector<unsigned char> jpeg;
    cv::imencode(".jpg", stored, jpeg, {cv::IMWRITE_JPEG_QUALITY, 100});
    streams.append(jpeg.begin(), jpeg.end());
    sizes.push_back(jpeg.size());
    std::string side;
    if (p == 4) {  // two texels set exactly: offset (big-endian), value
      f.planes[4][3] = 7;
      f.planes[4][static_cast<std::size_t>(w) * h - 1] = 250;
      side = std::string("\0\0\0\3\x07", 5) + std::string("\0\0", 2);
      const std::uint32_t last = static_cast<std::uint32_t>(w * h - 1);
      side += static_cast<char>(last >> 8 & 0xff);
      side += static_cast<char>(last & 0xff);
      side += static_cast<char>(250);
    }
    streams += side;
    side_sizes.push_back(side.size());
  }
  std::ostringstream out;
  auto line = [&](const auto& values) {
    for (std::size_t i = 0; i < values.size(); ++i) out << (i ? " " : "") << values[i];
    out << "\n";
  };
  out << "PTM_1.2\nPTM_FORMAT_JPEG_LRGB\n" << w << "\n" << h << "\n";
  line(std::vector<float>{2, 2, 2, 1, 1, 1});
  line(std::vector<int>{128, 128, 128, 0, 0, 0});
  out << "100\n";
  line(transform);
  line(std::vector<int>(n, 0));
  line(std::vector<int>(n, 0));
  line(order);
  line(reference);
  line(sizes);
  line(side_sizes);
  f.bytes = out.str() + streams;
  return f;
}

TEST(PtmFile, JpegLrgbDecodesPredictedInvertedAndCorrectedPlanes) {
  const int w = 24, h = 16;
  const JpegPtmFile f = MakeJpegLrgb(w, h);
  std::istringstream in(f.bytes);
  const Ptm ptm = ReadPtm(in, "jpeg.ptm");
  ASSERT_EQ(ptm.format, PtmFormat::kLrgb);
  ASSERT_EQ(ptm.width, w);
  float worst = 0.0f;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t t = static_cast<std::size_t>(y) * w + x;
      const std::size_t file_t = static_cast<std::size_t>(h - 1 - y) * w + x;  // rows bottom up
      const float scale[6] = {2, 2, 2, 1, 1, 1};
      const int bias[6] = {128, 128, 128, 0, 0, 0};
      for (int i = 0; i < 6; ++i) {
        const float expected =
            (f.planes[static_cast<std::size_t>(i)][file_t] - bias[i]) * scale[i] / 255.0f;
        const float error = std::abs(ptm.Coefficients(t)[i] - expected) * 255.0f / scale[i];
        worst = std::max(worst, error);
        if (i == 4 && (file_t == 3 || file_t == static_cast<std::size_t>(w * h - 1))) {
          EXPECT_EQ(error, 0.0f) << "side information is exact";
        }
      }
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(ptm.colour[t * 3 + static_cast<std::size_t>(c)] * 255.0f -
                                         f.planes[static_cast<std::size_t>(6 + c)][file_t]));
    }
  }
  EXPECT_LE(worst, 2.5f) << "levels of the 8-bit planes";  // JPEG at quality 100
}

TEST(PtmFile, JpegPtmsWithBadLayoutsAreRefusedNamingTheProblem) {
  const JpegPtmFile f = MakeJpegLrgb(24, 16);
  auto refused = [&](const std::string& from, const std::string& to) {
    std::string bytes = f.bytes;
    const std::size_t at = bytes.find(from);
    bytes.replace(at, from.size(), to);
    std::istringstream in(bytes);
    return testing::InputErrorMessage([&] { ReadPtm(in, "jpeg.ptm"); });
  };
  EXPECT_NE(refused("2 3 4 0 1 5 6 7 8", "2 3 4 0 1 5 6 7 7").find("permutation"),
            std::string::npos);
  EXPECT_NE(refused("-1 0 0 -1", "-1 5 0 -1").find("not decoded before"), std::string::npos);
  EXPECT_NE(refused("\n0 0 1 0 0 0 0 0 0\n", "\n0 0 2 0 0 0 0 0 0\n").find("transform 2"),
            std::string::npos);
  // Sizes whose sum wraps a 64-bit count are refused, not summed.
  const std::size_t sizes_line = f.bytes.find("\n", f.bytes.find("-1 0 0 -1")) + 1;
  std::string huge = f.bytes;
  huge.replace(sizes_line, huge.find("\n", sizes_line) - sizes_line,
               "9223372036854775807 9223372036854775807 1 1 1 1 1 1 1");
  std::istringstream huge_in(huge);
  EXPECT_NE(testing::InputErrorMessage([&] { ReadPtm(huge_in, "jpeg.ptm"); }).find("truncated"),
            std::string::npos);
  std::string truncated = f.bytes.substr(0, f.bytes.size() - 100);
  std::istringstream in(truncated);
  EXPECT_NE(testing::InputErrorMessage([&] { ReadPtm(in, "jpeg.ptm"); }).find("truncated"),
            std::string::npos);
  // A stream that is not the announced size of grey image.
  std::string wide = MakeJpegLrgb(24, 16).bytes;
  wide.replace(wide.find("\n24\n"), 4, "\n25\n");
  std::istringstream wide_in(wide);
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadPtm(wide_in, "jpeg.ptm");
            }).find("expected 25 x 16 grey"),
            std::string::npos);
}

TEST(PtmFile, ExrRoundTripIsLossless) {
  testing::TempDir tmp;
  for (auto format : {PtmFormat::kLrgb, PtmFormat::kRgb}) {
    const Ptm ptm = RandomPtm(format, 9, 7, 4);
    WritePtmExr(ptm, tmp / "p.exr");
    const Ptm back = ReadPtmExr(tmp / "p.exr");
    EXPECT_EQ(back.format, format);
    EXPECT_EQ(back.coefficients, ptm.coefficients);
    EXPECT_EQ(back.colour, ptm.colour);
  }
}

TEST(PtmFile, ExrFromMemoryEqualsExrFromFileAndOtherFormatsAreRefused) {
  testing::TempDir tmp;
  const Ptm ptm = RandomPtm(PtmFormat::kLrgb, 5, 3, 7);
  WritePtmExr(ptm, tmp / "p.exr");
  const std::string bytes = testing::ReadText(tmp / "p.exr");
  const Ptm back = ReadPtmExrBytes(bytes, "p.exr");
  EXPECT_EQ(back.coefficients, ptm.coefficients);
  EXPECT_EQ(back.colour, ptm.colour);
  // A whole PNG under an EXR's name, and an EXR cut short: refused, the file named; the
  // PNG as not an OpenEXR file (no other format's reader is tried).
  cv::imwrite((tmp / "image.png").string(), cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)));
  const std::string png = testing::ReadText(tmp / "image.png");
  const std::vector<std::string> damaged_files = {png, bytes.substr(0, bytes.size() / 2)};
  for (std::size_t i = 0; i < damaged_files.size(); ++i) {
    const std::string& damaged = damaged_files[i];
    testing::WriteText(tmp / "d.exr", damaged);
    const std::string from_file = testing::InputErrorMessage([&] { ReadPtmExr(tmp / "d.exr"); });
    const std::string from_memory =
        testing::InputErrorMessage([&] { ReadPtmExrBytes(damaged, "m.exr"); });
    EXPECT_NE(from_file.find("d.exr"), std::string::npos) << from_file;
    EXPECT_NE(from_memory.find("m.exr"), std::string::npos) << from_memory;
    if (i == 0) {
      EXPECT_NE(from_file.find("not an OpenEXR file"), std::string::npos) << from_file;
    }
  }
}

// OpenEXR would allocate what a header attribute declares before finding the file
// shorter (a 352-byte file declaring a 777 MB string took 893 MB), and reads typed
// attributes by their type (a 725-byte file asked for 1.9 GB so): the header is checked
// first, attribute by attribute, and so is the data window.
TEST(PtmFile, ExrHeadersDeclaringMoreThanTheFileHoldsAreRefusedFirst) {
  const auto int32 = [](std::int32_t v) {
    std::string b(4, '\0');
    for (int i = 0; i < 4; ++i) b[static_cast<std::size_t>(i)] = static_cast<char>(v >> (8 * i));
    return b;
  };
  const std::string head = int32(20000630) + int32(2);
  const std::string huge_string =
      head + std::string("capDate\0string\0", 15) + int32(776732672) + std::string(300, 'x');
  const std::string wide_window = head + std::string("dataWindow\0box2i\0", 17) + int32(16) +
                                  int32(0) + int32(0) + int32(1 << 20) + int32(9) + '\0';
  const std::string multi_part = int32(20000630) + int32(2 | 0x1000) + '\0';
  // Typed attributes are read by their type: a declared size that differs would leave
  // OpenEXR reading the rest of the header from another place than texlume's check.
  const std::string long_channel_list = head + std::string("channels\0chlist\0", 16) + int32(40) +
                                        std::string("R\0", 2) + std::string(17, '\0') +
                                        std::string(21, 'x') + '\0';
  const std::string long_compression =
      head + std::string("compression\0compression\0", 24) + int32(5) + std::string(5, '\0') + '\0';
  // A window within 65536 a side whose nine channels make more values than texlume reads:
  // refused from the header, before OpenEXR sizes its line buffers by it.
  std::string nine_channels;
  for (char c = 'a'; c < 'a' + 9; ++c)
    nine_channels += std::string{c, '\0'} + std::string(16, '\0');
  const std::string large_image = head + std::string("channels\0chlist\0", 16) + int32(9 * 18 + 1) +
                                  nine_channels + '\0' + std::string("dataWindow\0box2i\0", 17) +
                                  int32(16) + int32(0) + int32(0) + int32(59999) + int32(59999) +
                                  '\0';
  const std::vector<std::pair<std::string, std::string>> cases = {
      {huge_string, "'capDate' declares 776732672 bytes"},
      {wide_window, "1048577 x 10 pixels"},
      {multi_part, "multi-part"},
      {long_channel_list, "channel list does not take the bytes it declares"},
      {long_compression, "declares 5 bytes, not 1"},
      {large_image, "60000 x 60000 x 9 channels is more than texlume reads"},
      {head + "dataWin", "cut short"}};
  for (const auto& c : cases) {
    const std::string& bytes = c.first;  // a plain name: lambdas capture it (clang 14)
    const std::string error = testing::InputErrorMessage([&] { ReadPtmExrBytes(bytes, "h.exr"); });
    EXPECT_EQ(error.rfind("h.exr", 0), 0u) << error;
    EXPECT_NE(error.find(c.second), std::string::npos) << error;
  }
}

TEST(PtmFile, RelightWebExportWritesInfoAndPlanes) {
  testing::TempDir tmp;
  const Ptm ptm = RandomPtm(PtmFormat::kRgb, 16, 8, 5);
  EXPECT_EQ(WriteRelightWeb(ptm, tmp / "web"), 7);
  const auto info = nlohmann::json::parse(testing::ReadText(tmp / "web/info.json"));
  EXPECT_EQ(info["type"], "ptm");
  EXPECT_EQ(info["colorspace"], "rgb");
  EXPECT_EQ(info["nplanes"], 18);
  EXPECT_EQ(info["materials"][0]["scale"].size(), 18u);
  EXPECT_TRUE(std::filesystem::exists(tmp / "web/plane_5.jpg"));
  // LRGB goes out as its RGB equivalent, which OpenLIME draws right (its "lrgb" shader
  // makes the luminance the pixel's alpha).
  const Ptm lrgb = RandomPtm(PtmFormat::kLrgb, 16, 8, 6);
  EXPECT_EQ(WriteRelightWeb(lrgb, tmp / "web2"), 7);
  const auto info2 = nlohmann::json::parse(testing::ReadText(tmp / "web2/info.json"));
  EXPECT_EQ(info2["colorspace"], "rgb");
  EXPECT_EQ(info2["nplanes"], 18);
}

TEST(Ptm, AnLrgbPtmAsRgbRelightsTheSame) {
  const Ptm lrgb = RandomPtm(PtmFormat::kLrgb, 6, 5, 7);
  const Ptm rgb = AsRgb(lrgb);
  ASSERT_EQ(rgb.format, PtmFormat::kRgb);
  for (const Eigen::Vector3d& light :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.6, -0.3, 0.74)}) {
    const std::vector<float> a = Relight(lrgb, light.normalized()),
                             b = Relight(rgb, light.normalized());
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-5f) << i;
  }
}

}  // namespace
}  // namespace texlume::ptm
