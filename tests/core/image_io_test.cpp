#include "core/image_io.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "core/errors.h"
#include "tests/test_util.h"

namespace texlume {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;

// A JPEG of 16 x 8 stored pixels, left half red and right half blue, whose
// EXIF orientation tag says 6 (to be shown turned 90 degrees clockwise).
fs::path WriteJpegWithOrientation6(const fs::path& path) {
  const int w = 16, h = 8;
  std::vector<unsigned char> rgb(static_cast<std::size_t>(w * h * 3), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      rgb[static_cast<std::size_t>((y * w + x) * 3 + (x < w / 2 ? 0 : 2))] = 255;
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("Orientation", 6);
  spec.attribute("CompressionQuality", 100);
  auto out = OIIO::ImageOutput::create(path.string());
  EXPECT_TRUE(out && out->open(path.string(), spec) &&
              out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) && out->close());
  return path;
}

TEST(ImageIo, PixelsStayInStoredOrderWhateverTheExifOrientationSays) {
  TempDir tmp;
  const fs::path jpeg = WriteJpegWithOrientation6(tmp.path() / "turned.jpg");
  {  // The file really carries orientation 6, and a reader that honours it turns the image.
    auto in = OIIO::ImageInput::open(jpeg.string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().get_int_attribute("Orientation"), 6);
    const cv::Mat turned = cv::imread(jpeg.string(), cv::IMREAD_COLOR);
    EXPECT_EQ(turned.cols, 8);
    EXPECT_EQ(turned.rows, 16);
  }
  // texlume (as COLMAP 3.8) keeps the stored order: 16 x 8, red on the left.
  const cv::Mat rgb = ReadPhotoRgb(jpeg);
  ASSERT_EQ(rgb.cols, 16);
  ASSERT_EQ(rgb.rows, 8);
  const cv::Vec3f left = rgb.at<cv::Vec3f>(4, 2), right = rgb.at<cv::Vec3f>(4, 13);
  EXPECT_GT(left[0], 0.8f);
  EXPECT_LT(left[2], 0.2f);
  EXPECT_LT(right[0], 0.2f);
  EXPECT_GT(right[2], 0.8f);
  ImageReader rows(jpeg);
  EXPECT_EQ(rows.width(), 16);
  EXPECT_EQ(rows.height(), 8);
  const cv::Mat grey = ReadImageGrey(jpeg);
  EXPECT_EQ(grey.size(), cv::Size(16, 8));
}

TEST(ImageIo, IntegersAreScaledToUnitAndChannelsMadeRgb) {
  TempDir tmp;
  // 16-bit grey: each value v becomes v / 65535 in all three channels.
  cv::Mat grey16(2, 3, CV_16UC1);
  for (int i = 0; i < 6; ++i)
    grey16.at<std::uint16_t>(i / 3, i % 3) = static_cast<std::uint16_t>(i * 13107);
  ASSERT_TRUE(cv::imwrite((tmp.path() / "g16.png").string(), grey16));
  const cv::Mat rgb = ReadPhotoRgb(tmp.path() / "g16.png");
  ASSERT_EQ(rgb.type(), CV_32FC3);
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_FLOAT_EQ(rgb.at<cv::Vec3f>(i / 3, i % 3)[c], i * 13107 / 65535.0f);
  // 8-bit BGRA as OpenCV writes it: RGB in order, alpha dropped; grey is the Rec. 601 luma.
  cv::Mat bgra(1, 2, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  bgra.at<cv::Vec4b>(0, 0) = cv::Vec4b(30, 60, 90, 10);  // B G R A
  bgra.at<cv::Vec4b>(0, 1) = cv::Vec4b(255, 255, 255, 255);
  ASSERT_TRUE(cv::imwrite((tmp.path() / "c8.png").string(), bgra));
  const cv::Mat c8 = ReadPhotoRgb(tmp.path() / "c8.png");
  EXPECT_FLOAT_EQ(c8.at<cv::Vec3f>(0, 0)[0], 90 / 255.0f);
  EXPECT_FLOAT_EQ(c8.at<cv::Vec3f>(0, 0)[1], 60 / 255.0f);
  EXPECT_FLOAT_EQ(c8.at<cv::Vec3f>(0, 0)[2], 30 / 255.0f);
  const cv::Mat luma = ReadImageGrey(tmp.path() / "c8.png");
  EXPECT_NEAR(luma.at<float>(0, 0), (0.299 * 90 + 0.587 * 60 + 0.114 * 30) / 255.0, 1e-6);
  EXPECT_NEAR(luma.at<float>(0, 1), 1.0, 1e-6);
}

TEST(ImageIo, MissingAndBrokenFilesAreInputErrorsNamingThem) {
  TempDir tmp;
  const fs::path missing = tmp.path() / "missing.png";
  try {
    ReadPhotoRgb(missing);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), missing.string());
  }
  const fs::path broken = tmp.path() / "broken.png";
  WriteBytesAtomically(broken, {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0});
  EXPECT_THROW(ReadPhotoRgb(broken), InputError);
  EXPECT_THROW(ImageReader{broken}, InputError);
}

}  // namespace
}  // namespace texlume

namespace texlume {
namespace {

// The sRGB curves by their definition (IEC 61966-2-1), in double.
double DecodeByDefinition(double v) {
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}
double EncodeByDefinition(double v) {
  return v <= 0.0031308 ? v * 12.92 : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

TEST(Srgb, TransfersFollowTheStandardCurvesWithinAFloatsRounding) {
  double worst_decode = 0.0, worst_encode = 0.0;
  for (int i = 0; i <= 1000000; ++i) {
    const double v = i / 1000000.0;
    worst_decode = std::max(worst_decode, std::abs(SrgbToLinear(static_cast<float>(v)) -
                                                   DecodeByDefinition(static_cast<float>(v))));
    worst_encode = std::max(worst_encode, std::abs(LinearToSrgb(static_cast<float>(v)) -
                                                   EncodeByDefinition(static_cast<float>(v))));
  }
  EXPECT_LT(worst_decode, 1e-7);
  EXPECT_LT(worst_encode, 1e-7);
  // Ends, clamping, NaN and the round trip.
  EXPECT_FLOAT_EQ(SrgbToLinear(1.0f), 1.0f);
  EXPECT_FLOAT_EQ(LinearToSrgb(1.0f), 1.0f);
  EXPECT_EQ(SrgbToLinear(-0.5f), 0.0f);
  EXPECT_EQ(LinearToSrgb(2.0f), 1.0f);
  EXPECT_EQ(SrgbToLinear(std::nanf("")), 0.0f);
  EXPECT_EQ(LinearToSrgb(std::nanf("")), 0.0f);
  for (float v = 0.0f; v <= 1.0f; v += 0.001f) EXPECT_NEAR(LinearToSrgb(SrgbToLinear(v)), v, 2e-6);
}

}  // namespace
}  // namespace texlume
