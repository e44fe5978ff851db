#include "ptm/image_bands.h"

#include <algorithm>
#include <exception>
#include <string>
#include <thread>

#include "core/errors.h"

namespace texlume::ptm {

ImageBands::ImageBands(const std::vector<std::filesystem::path>& files) {
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
}

void ImageBands::Read(int y0, int band_rows, std::vector<std::vector<float>>& band) {
  const int rows = std::min(band_rows, height_ - y0);
  for (std::size_t k = 0; k < inputs_.size(); ++k)
    inputs_[k].ReadRows(y0, y0 + rows, 3, band[k].data());
}

void ImageBands::ForEach(
    int band_rows,
    const std::function<void(const std::vector<const float*>& pixels, int y0, int rows)>& process,
    const ProgressCallback& progress, const char* stage) {
  const std::size_t band_floats = static_cast<std::size_t>(band_rows) * width_ * 3;
  // Two bands: the next one is decoded while the current one is processed.
  std::vector<std::vector<float>> bands[2];
  for (auto& set : bands) set.assign(inputs_.size(), std::vector<float>(band_floats));
  if (height_ > 0) Read(0, band_rows, bands[0]);
  for (int b = 0, y0 = 0; y0 < height_; ++b, y0 += band_rows) {
    const int rows = std::min(band_rows, height_ - y0);
    const int next = y0 + band_rows;
    std::exception_ptr read_error;
    std::thread reader;
    if (next < height_) {
      reader = std::thread([&, next, b] {
        try {
          Read(next, band_rows, bands[(b + 1) % 2]);
        } catch (...) {
          read_error = std::current_exception();
        }
      });
    }
    std::vector<const float*> pixels;
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

}  // namespace texlume::ptm
