#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/srgb.h"

namespace texlume {

/// sRGB decoding and encoding of display values in [0, 1] (IEC 61966-2-1);
/// inputs outside [0, 1] are clamped, NaN is 0. Within 1e-7 of the curves
/// (tabulated: core/srgb.h; inline, as the loops over texels call them). Photos
/// and PTMs hold display values; light mixtures are summed in the linear domain
/// (DESIGN.md, "Frames, units").
inline float SrgbToLinear(float v) { return srgb::ToLinear(v); }
inline float LinearToSrgb(float v) { return srgb::FromLinear(v); }

/// texlume's one image reader (OpenImageIO: PNG, JPEG, TIFF, EXR, ...), with
/// one orientation policy: pixels are taken in the order the file stores them
/// and the EXIF orientation tag is ignored, as COLMAP 3.8 reads images
/// (FreeImage without JPEG_EXIFROTATE), so that pixel (x, y) of a photo is the
/// one the model's camera projects to. Values are display values in [0, 1]:
/// 8- and 16-bit integers scaled by 1/255 and 1/65535, floats as stored.
/// Throws InputError naming the file when it is missing or unreadable, or its
/// size or channel count is implausible (over 65536 a side, 0 or over 64
/// channels).
class ImageReader {
 public:
  explicit ImageReader(const std::filesystem::path& path);
  ~ImageReader();
  ImageReader(ImageReader&&) noexcept;
  ImageReader& operator=(ImageReader&&) noexcept;

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  /// Whether the file stores 8-bit samples (JPEG, most PNGs and TIFFs).
  bool eight_bit() const { return eight_bit_; }
  const std::filesystem::path& path() const { return path_; }

  /// Rows [y0, y1) into `out` (row-major, `channels` floats per pixel): the
  /// file's first channels; a grey file's channel repeated.
  void ReadRows(int y0, int y1, int channels, float* out);
  /// The same as 8-bit values (0..255, the file's own for an eight_bit() file:
  /// no conversion on the way).
  void ReadRows(int y0, int y1, int channels, std::uint8_t* out);

 private:
  template <typename Sample>
  void ReadRowsAs(int y0, int y1, int channels, Sample* out);

  struct Input;
  std::unique_ptr<Input> in_;
  std::filesystem::path path_;
  int width_ = 0, height_ = 0, channels_ = 0;
  bool eight_bit_ = false;
};

/// An 8-bit grey image of exactly `width` x `height` pixels decoded from `bytes`
/// held in memory by OpenImageIO's reader for `format` ("jpeg", "png"), as
/// CV_8UC1 in the order the stream stores its rows. The size and channel count are
/// checked before anything is decoded; InputError naming `label` when the bytes are
/// not such an image.
cv::Mat DecodeGreyImageBytes(std::string_view bytes, const char* format, int width, int height,
                             const std::string& label);

/// A photo as CV_32FC3 RGB display values in [0, 1] (ImageReader; grey
/// repeated, alpha dropped).
cv::Mat ReadPhotoRgb(const std::filesystem::path& path);
/// The same photo in its stored sample type, 3 channels (CV_8UC3, CV_16UC3 or
/// CV_32FC3): a quarter of the memory for an 8-bit file (the photo cache keeps it so).
cv::Mat ReadPhotoNative(const std::filesystem::path& path);
/// ReadPhotoNative's pixels (or a part of them) as ReadPhotoRgb gives them: the same
/// values; a CV_32FC3 image is returned as it is, without a copy.
cv::Mat PhotoDisplayRgb(const cv::Mat& native);

/// An image as CV_32FC1 values in [0, 1]: a grey file's channel, or the luma of
/// an RGB one (Rec. 601: 0.299 R + 0.587 G + 0.114 B). Masks and the
/// highlight-sphere photos.
cv::Mat ReadImageGrey(const std::filesystem::path& path);

/// 8-bit BGR (for PNG) of a CV_32FC3 display RGB image in [0, 1].
cv::Mat ToBgr8(const cv::Mat& display_rgb);

/// PNG bytes of an 8- or 16-bit image; throws InputError(label) on failure.
std::vector<unsigned char> EncodePng(const cv::Mat& image, const std::string& label);

/// Writes bytes under a temporary name, then renames (no half-written file).
void WriteBytesAtomically(const std::filesystem::path& path,
                          const std::vector<unsigned char>& bytes);

}  // namespace texlume
