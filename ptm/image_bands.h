#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "core/image_io.h"
#include "core/progress.h"

namespace texlume::ptm {

/// How a band's pixels are laid out: RGB interleaved, or an image's band as its R
/// plane, then its G plane, then its B plane (rows x width each).
enum class BandLayout { kInterleaved, kPlanar };

/// An RTI capture's images read together a band of rows at a time (the one image
/// reader, core/image_io.h), so that fitting needs memory for one band of every
/// image, not for every image. The next band is decoded while the current one is
/// processed, its images shared among `decode_threads` threads.
class ImageBands {
 public:
  /// Opens every file; throws InputError naming a file whose size differs from the
  /// first one's. decode_threads 0: as many as OpenMP's threads.
  explicit ImageBands(const std::vector<std::filesystem::path>& files, int decode_threads = 0);

  int width() const { return width_; }
  int height() const { return height_; }
  /// Whether every file stores 8-bit samples, so that ForEach<std::uint8_t> reads
  /// them without conversion.
  bool eight_bit() const;

  /// Calls `process(pixels, y0, rows)` for each band of `band_rows` rows, top to
  /// bottom: pixels[k] holds image k's rows [y0, y0 + rows) in `layout`, floats in
  /// [0, 1] or 8-bit values 0..255 (Sample float or std::uint8_t). Planes are made
  /// by the decoding threads. Reports progress as `stage` over the rows.
  template <typename Sample>
  void ForEach(int band_rows,
               const std::function<void(const std::vector<const Sample*>& pixels, int y0,
                                        int rows)>& process,
               const ProgressCallback& progress, const char* stage,
               BandLayout layout = BandLayout::kInterleaved);

 private:
  template <typename Sample>
  void Read(int y0, int band_rows, BandLayout layout, std::vector<std::vector<Sample>>& band);
  std::vector<ImageReader> inputs_;
  int width_ = 0, height_ = 0;
  int decode_threads_ = 1;
};

}  // namespace texlume::ptm
