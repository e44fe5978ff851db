#include "ptm/image_bands.h"

#include <omp.h>

#include <algorithm>
#include <exception>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <type_traits>

#include "core/errors.h"

namespace texlume::ptm {

ImageBands::ImageBands(const std::vector<std::filesystem::path>& files, int decode_threads) {
  for (const auto& file : files) {
    ImageReader in(file);
    if (inputs_.empty()) {
      width_ = in.width();
      height_ = in.height();
    } else if (in.width() != width_ || in.height() != height_) {
      throw InputError(file.string(), "is " + std::to_string(in.width()) + "x" +
                                          std::to_string(in.height()) + " but " +
                                          files[0].string() + " is " + std::to_string(width_) +
                                          "x" + std::to_string(height_));
    }
    inputs_.push_back(std::move(in));
  }
  // As many as the fit's OpenMP team (OMP_NUM_THREADS, else one per hardware thread).
  decode_threads_ = std::clamp(decode_threads > 0 ? decode_threads : omp_get_max_threads(), 1,
                               std::max(1, static_cast<int>(inputs_.size())));
}

bool ImageBands::eight_bit() const {
  return std::all_of(inputs_.begin(), inputs_.end(),
                     [](const ImageReader& in) { return in.eight_bit(); });
}

namespace {

// Image k's rows [y0, y0 + rows) as three planes: decoded interleaved into
// `scratch`, then split.
template <typename Sample>
void ReadPlanes(ImageReader& input, int y0, int rows, std::vector<Sample>& scratch,
                Sample* planes) {
  const int type = std::is_same_v<Sample, float> ? CV_32FC3 : CV_8UC3;
  const int plane_type = std::is_same_v<Sample, float> ? CV_32FC1 : CV_8UC1;
  const int width = input.width();
  input.ReadRows(y0, y0 + rows, 3, scratch.data());
  const std::size_t plane = static_cast<std::size_t>(rows) * static_cast<std::size_t>(width);
  cv::Mat split[3];
  for (std::size_t ch = 0; ch < 3; ++ch)
    split[ch] = cv::Mat(rows, width, plane_type, planes + ch * plane);
  cv::split(cv::Mat(rows, width, type, scratch.data()), split);
}

}  // namespace

// Images k = t, t + T, t + 2T, ... on thread t: each image's reader decodes its
// rows in order, on one thread at a time.
template <typename Sample>
void ImageBands::Read(int y0, int band_rows, BandLayout layout,
                      std::vector<std::vector<Sample>>& band) {
  const int rows = std::min(band_rows, height_ - y0);
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(decode_threads_));
  auto decode = [&](int t) {
    try {
      std::vector<Sample> scratch;
      if (layout == BandLayout::kPlanar) scratch.resize(band.empty() ? 0 : band[0].size());
      for (std::size_t k = static_cast<std::size_t>(t); k < inputs_.size();
           k += static_cast<std::size_t>(decode_threads_)) {
        if (layout == BandLayout::kPlanar) {
          ReadPlanes(inputs_[k], y0, rows, scratch, band[k].data());
        } else {
          inputs_[k].ReadRows(y0, y0 + rows, 3, band[k].data());
        }
      }
    } catch (...) {
      errors[static_cast<std::size_t>(t)] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  try {
    for (int t = 1; t < decode_threads_; ++t) threads.emplace_back(decode, t);
  } catch (...) {  // a thread that cannot start: join those that did
    for (auto& thread : threads) thread.join();
    throw;
  }
  decode(0);
  for (auto& thread : threads) thread.join();
  for (const auto& error : errors)
    if (error) std::rethrow_exception(error);
}

template <typename Sample>
void ImageBands::ForEach(
    int band_rows,
    const std::function<void(const std::vector<const Sample*>& pixels, int y0, int rows)>& process,
    const ProgressCallback& progress, const char* stage, BandLayout layout) {
  const std::size_t band_samples = static_cast<std::size_t>(band_rows) * width_ * 3;
  // Two bands: the next one is decoded while the current one is processed.
  std::vector<std::vector<Sample>> bands[2];
  for (auto& set : bands) set.assign(inputs_.size(), std::vector<Sample>(band_samples));
  if (height_ > 0) Read(0, band_rows, layout, bands[0]);
  for (int b = 0, y0 = 0; y0 < height_; ++b, y0 += band_rows) {
    const int rows = std::min(band_rows, height_ - y0);
    const int next = y0 + band_rows;
    std::exception_ptr read_error;
    std::thread reader;
    if (next < height_) {
      reader = std::thread([&, next, b] {
        try {
          Read(next, band_rows, layout, bands[(b + 1) % 2]);
        } catch (...) {
          read_error = std::current_exception();
        }
      });
    }
    std::vector<const Sample*> pixels;
    for (const auto& image_band : bands[b % 2]) pixels.push_back(image_band.data());
    try {
      process(pixels, y0, rows);
    } catch (...) {
      if (reader.joinable()) reader.join();
      throw;
    }
    if (reader.joinable()) reader.join();
    if (read_error) std::rethrow_exception(read_error);
    if (progress)
      progress(stage, static_cast<std::size_t>(y0 + rows), static_cast<std::size_t>(height_));
  }
}

template void ImageBands::ForEach<float>(
    int, const std::function<void(const std::vector<const float*>&, int, int)>&,
    const ProgressCallback&, const char*, BandLayout);
template void ImageBands::ForEach<std::uint8_t>(
    int, const std::function<void(const std::vector<const std::uint8_t*>&, int, int)>&,
    const ProgressCallback&, const char*, BandLayout);

}  // namespace texlume::ptm
