#include "core/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <type_traits>

#include "core/bounded_memory_reader.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/memory_budget.h"

namespace texlume {
namespace fs = std::filesystem;

namespace {

// Opens an image with OpenImageIO and checks what its header announces.
std::unique_ptr<OIIO::ImageInput> OpenChecked(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path.string(), "does not exist");
  // Colour as stored: no premultiplication by an alpha channel.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  if (!in) throw InputError(path.string(), "is not a readable image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  // At most 65,536 a side and 250 megapixels (docs/robustness.md, "Limits").
  if (spec.width <= 0 || spec.height <= 0 || spec.width > 65536 || spec.height > 65536 ||
      static_cast<std::int64_t>(spec.width) * spec.height > 250'000'000)
    throw InputError(path.string(), "has an implausible size of " + std::to_string(spec.width) +
                                        " x " + std::to_string(spec.height) + " pixels");
  if (spec.nchannels <= 0 || spec.nchannels > 64)
    throw InputError(path.string(),
                     "has an implausible channel count of " + std::to_string(spec.nchannels));
  // As stored, then as float RGB.
  RequireMemory(static_cast<double>(spec.width) * spec.height * (spec.nchannels * 4.0 + 12.0),
                "reading the image", path.string());
  return in;
}

// The whole image with its first min(channels, 3) channels in their stored
// type (8- or 16-bit integers; anything else as float), rows top to bottom.
cv::Mat ReadNative(const fs::path& path) {
  const std::unique_ptr<OIIO::ImageInput> in = OpenChecked(path);
  const OIIO::ImageSpec& spec = in->spec();
  const int channels = std::min(spec.nchannels, 3);
  OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT;
  int depth = CV_32F;
  if (spec.format == OIIO::TypeDesc::UINT8) {
    type = OIIO::TypeDesc::UINT8, depth = CV_8U;
  } else if (spec.format == OIIO::TypeDesc::UINT16) {
    type = OIIO::TypeDesc::UINT16, depth = CV_16U;
  }
  cv::Mat image(spec.height, spec.width, CV_MAKETYPE(depth, channels));
  if (!in->read_image(0, 0, 0, channels, type, image.data))
    throw InputError(path.string(), "cannot read its pixels: " + in->geterror());
  return image;
}

double ScaleToUnit(int depth) {
  return depth == CV_8U ? 1.0 / 255.0 : depth == CV_16U ? 1.0 / 65535.0 : 1.0;
}

}  // namespace

cv::Mat DecodeGreyImageBytes(std::string_view bytes, const char* format, int width, int height,
                             const std::string& label) {
  BoundedMemoryReader memory(bytes);  // outlives the reader, which reads it when it closes
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::create(format);
  if (!in)
    throw std::runtime_error(std::string("OpenImageIO was built without its ") + format +
                             " reader");
  if (!in->set_ioproxy(&memory))
    throw std::runtime_error(std::string("OpenImageIO's ") + format +
                             " reader cannot read from memory");
  OIIO::ImageSpec spec;
  if (!in->open(std::string(), spec)) {
    std::string error = in->geterror();
    if (error.empty()) error = OIIO::geterror();
    throw InputError(label, std::string("is not a readable ") + format + " stream: " + error);
  }
  if (spec.width != width || spec.height != height || spec.nchannels != 1)
    throw InputError(label, "is a " + std::to_string(spec.width) + " x " +
                                std::to_string(spec.height) + " image of " +
                                std::to_string(spec.nchannels) + " channel(s); expected " +
                                std::to_string(width) + " x " + std::to_string(height) + " grey");
  cv::Mat image(height, width, CV_8UC1);
  if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, image.data))
    throw InputError(label, "cannot decode its pixels: " + in->geterror());
  return image;
}

struct ImageReader::Input {
  std::unique_ptr<OIIO::ImageInput> in;
};

ImageReader::ImageReader(const fs::path& path)
    : in_(std::make_unique<Input>(Input{OpenChecked(path)})), path_(path) {
  const OIIO::ImageSpec& spec = in_->in->spec();
  width_ = spec.width;
  height_ = spec.height;
  channels_ = spec.nchannels;
  eight_bit_ = spec.format == OIIO::TypeDesc::UINT8;
}

ImageReader::~ImageReader() = default;
ImageReader::ImageReader(ImageReader&&) noexcept = default;
ImageReader& ImageReader::operator=(ImageReader&&) noexcept = default;

template <typename Sample>
void ImageReader::ReadRowsAs(int y0, int y1, int channels, Sample* out) {
  const OIIO::TypeDesc type =
      std::is_same_v<Sample, float> ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
  const int read = std::min(channels_, channels);
  const std::size_t pixels = static_cast<std::size_t>(y1 - y0) * static_cast<std::size_t>(width_);
  std::vector<Sample> raw;
  Sample* target = out;
  if (read != channels) {
    raw.resize(pixels * static_cast<std::size_t>(read));
    target = raw.data();
  }
  if (!in_->in->read_scanlines(0, 0, y0, y1, 0, 0, read, type, target))
    throw InputError(path_.string(), "cannot read rows " + std::to_string(y0) + ".." +
                                         std::to_string(y1) + ": " + in_->in->geterror());
  if (read == channels) return;
  for (std::size_t i = 0; i < pixels; ++i)
    for (int c = 0; c < channels; ++c)
      out[i * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c)] =
          raw[i * static_cast<std::size_t>(read) + static_cast<std::size_t>(std::min(c, read - 1))];
}

void ImageReader::ReadRows(int y0, int y1, int channels, float* out) {
  ReadRowsAs(y0, y1, channels, out);
}

void ImageReader::ReadRows(int y0, int y1, int channels, std::uint8_t* out) {
  ReadRowsAs(y0, y1, channels, out);
}

cv::Mat ReadPhotoNative(const fs::path& path) {
  cv::Mat image = ReadNative(path);
  if (image.channels() == 1) {
    cv::Mat rgb;
    cv::merge(std::vector<cv::Mat>{image, image, image}, rgb);
    return rgb;
  }
  if (image.channels() == 2) {
    cv::Mat grey;
    cv::extractChannel(image, grey, 0);
    cv::merge(std::vector<cv::Mat>{grey, grey, grey}, image);
  }
  return image;
}

cv::Mat PhotoDisplayRgb(const cv::Mat& native) {
  if (native.type() == CV_32FC3) return native;
  cv::Mat rgb;
  native.convertTo(rgb, CV_32FC3, ScaleToUnit(native.depth()));
  return rgb;
}

cv::Mat ReadPhotoRgb(const fs::path& path) {
  cv::Mat rgb;
  const cv::Mat native = ReadPhotoNative(path);
  native.convertTo(rgb, CV_32FC3, ScaleToUnit(native.depth()));
  return rgb;
}

cv::Mat ReadImageGrey(const fs::path& path) {
  const cv::Mat image = ReadNative(path);
  cv::Mat f;
  image.convertTo(f, CV_MAKETYPE(CV_32F, image.channels()), ScaleToUnit(image.depth()));
  if (f.channels() < 3) {
    cv::Mat grey;
    cv::extractChannel(f, grey, 0);
    return grey;
  }
  cv::Mat grey;
  cv::transform(f, grey, cv::Matx13f(0.299f, 0.587f, 0.114f));
  return grey;
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
