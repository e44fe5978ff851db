#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace texlume {

/// sRGB decoding and encoding of display values in [0, 1] (IEC 61966-2-1);
/// inputs outside [0, 1] are clamped. Photos and PTMs hold display values;
/// light mixtures are summed in the linear domain (DESIGN.md, "Frames, units").
float SrgbToLinear(float v);
float LinearToSrgb(float v);

/// Reads a photo as CV_32FC3 RGB display values in [0, 1] (8- or 16-bit
/// integers scaled, float taken as is; grey and RGBA become RGB).
/// Throws InputError naming the file when it is missing, unreadable, or of an
/// unsupported channel count or pixel type.
cv::Mat ReadPhotoRgb(const std::filesystem::path& path);

/// 8-bit BGR (for PNG) of a CV_32FC3 display RGB image in [0, 1].
cv::Mat ToBgr8(const cv::Mat& display_rgb);

/// PNG bytes of an 8- or 16-bit image; throws InputError(label) on failure.
std::vector<unsigned char> EncodePng(const cv::Mat& image, const std::string& label);

/// Writes bytes under a temporary name, then renames (no half-written file).
void WriteBytesAtomically(const std::filesystem::path& path,
                          const std::vector<unsigned char>& bytes);

}  // namespace texlume
