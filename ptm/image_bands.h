#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "core/image_io.h"
#include "core/progress.h"

namespace texlume::ptm {

/// How a band's pixels are laid out: RGB interleaved, or each row as its R values,
/// then its G values, then its B values (width each). Either way rows follow one
/// another, so that rows [r, r + n) of a band are a band of n rows themselves.
enum class BandLayout { kInterleaved, kRowPlanar };

/// An RTI capture's images read together a band of rows at a time (the one image
/// reader, core/image_io.h), so that fitting needs memory for one band of every
/// image, not for every image. The next band is decoded while the current one is
/// processed: one OpenMP team runs both as tasks (each image's rows of the next band,
/// and a few rows of the current band at a time), so that neither waits for the
/// other and the threads are never more than the cores.
class ImageBands {
 public:
  /// Opens every file; throws InputError naming a file whose size differs from the
  /// first one's. threads 0: as many as OpenMP's threads.
  explicit ImageBands(const std::vector<std::filesystem::path>& files, int threads = 0);

  int width() const { return width_; }
  int height() const { return height_; }
  /// Whether every file stores 8-bit samples, so that ForEach<std::uint8_t> reads
  /// them without conversion.
  bool eight_bit() const;

  /// Calls `process(pixels, y0, rows)` for every row once, a few rows at a time:
  /// pixels[k] holds image k's rows [y0, y0 + rows) in `layout`, floats in [0, 1] or
  /// 8-bit values 0..255 (Sample float or std::uint8_t). Calls for rows of the same
  /// band run on several threads at once, so `process` must be safe for that (it
  /// writes only its own rows' results); the first exception thrown by a call or a
  /// read ends the loop and is rethrown. Reports progress as `stage` over the rows,
  /// band by band.
  template <typename Sample>
  void ForEach(int band_rows,
               const std::function<void(const std::vector<const Sample*>& pixels, int y0,
                                        int rows)>& process,
               const ProgressCallback& progress, const char* stage,
               BandLayout layout = BandLayout::kInterleaved);

 private:
  std::vector<ImageReader> inputs_;
  int width_ = 0, height_ = 0;
  int threads_ = 1;
};

}  // namespace texlume::ptm
