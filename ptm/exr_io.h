#pragma once

#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace texlume::ptm {

/// Writes a float image (CV_32FC1..CV_32FC4, or a vector of CV_32FC1 planes) as a
/// lossless (PIZ-compressed) OpenEXR file with the given channel names, through
/// OpenImageIO, atomically. Throws std::runtime_error naming the file on failure.
/// `float_attributes` go into the header as float attributes (names "texlume:...").
void WriteExr(const std::filesystem::path& path, const std::vector<cv::Mat>& planes,
              const std::vector<std::string>& channel_names,
              const std::map<std::string, float>& float_attributes = {});

/// Reads every channel of an OpenEXR file as float planes, and their names, through
/// OpenImageIO's OpenEXR reader only. Throws InputError naming the file when it is not
/// a readable OpenEXR file or declares an implausible size (docs/robustness.md).
/// `float_attributes`, when given, receives the header's float attributes named
/// "texlume:...".
std::vector<cv::Mat> ReadExr(const std::filesystem::path& path,
                             std::vector<std::string>* channel_names = nullptr,
                             std::map<std::string, float>* float_attributes = nullptr);

/// ReadExr on the bytes of an OpenEXR file in memory; errors name `label`.
std::vector<cv::Mat> ReadExrBytes(std::string_view bytes, const std::string& label,
                                  std::vector<std::string>* channel_names = nullptr);

}  // namespace texlume::ptm
