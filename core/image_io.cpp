#include "core/image_io.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "core/file_util.h"

namespace texlume {
namespace fs = std::filesystem;

float SrgbToLinear(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? v * 12.92f : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

cv::Mat ReadPhotoRgb(const fs::path& path) {
  if (!fs::exists(path)) throw InputError(path.string(), "does not exist");
  const cv::Mat raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
  if (raw.empty()) throw InputError(path.string(), "is not a readable image");
  cv::Mat bgr;
  if (raw.channels() == 1) {
    cv::cvtColor(raw, bgr, cv::COLOR_GRAY2BGR);
  } else if (raw.channels() == 4) {
    cv::cvtColor(raw, bgr, cv::COLOR_BGRA2BGR);
  } else if (raw.channels() == 3) {
    bgr = raw;
  } else {
    throw InputError(path.string(), "has " + std::to_string(raw.channels()) + " channels");
  }
  double scale = 1.0;
  switch (bgr.depth()) {
    case CV_8U:
      scale = 1.0 / 255.0;
      break;
    case CV_16U:
      scale = 1.0 / 65535.0;
      break;
    case CV_32F:
      scale = 1.0;
      break;
    default:
      throw InputError(path.string(), "has an unsupported pixel type");
  }
  cv::Mat f, rgb;
  bgr.convertTo(f, CV_32FC3, scale);
  cv::cvtColor(f, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

cv::Mat ToBgr8(const cv::Mat& display_rgb) {
  cv::Mat bgr, out;
  cv::cvtColor(display_rgb, bgr, cv::COLOR_RGB2BGR);
  bgr.convertTo(out, CV_8UC3, 255.0);
  return out;
}

std::vector<unsigned char> EncodePng(const cv::Mat& image, const std::string& label) {
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", image, png)) throw InputError(label, "PNG encoding failed");
  return png;
}

void WriteBytesAtomically(const fs::path& path, const std::vector<unsigned char>& bytes) {
  WriteFileAtomically(
      path,
      [&](std::ostream& out) {
        out.write(reinterpret_cast<const char*>(bytes.data()),
                  static_cast<std::streamsize>(bytes.size()));
      },
      true);
}

}  // namespace texlume
