#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "core/image_io.h"
#include "core/progress.h"

namespace texlume::ptm {

/// An RTI capture's images read together a band of rows at a time (the one image
/// reader, core/image_io.h), so that fitting needs memory for one band of every
/// image, not for every image. The next band is decoded while the current one is
/// processed.
class ImageBands {
 public:
  /// Opens every file; throws InputError naming a file whose size differs from the
  /// first one's.
  explicit ImageBands(const std::vector<std::filesystem::path>& files);

  int width() const { return width_; }
  int height() const { return height_; }

  /// Calls `process(pixels, y0, rows)` for each band of `band_rows` rows, top to
  /// bottom: pixels[k] holds image k's rows [y0, y0 + rows) as RGB floats in [0, 1].
  /// Reports progress as `stage` over the rows.
  void ForEach(
      int band_rows,
      const std::function<void(const std::vector<const float*>& pixels, int y0, int rows)>& process,
      const ProgressCallback& progress, const char* stage);

 private:
  void Read(int y0, int band_rows, std::vector<std::vector<float>>& band);
  std::vector<ImageReader> inputs_;
  int width_ = 0, height_ = 0;
};

}  // namespace texlume::ptm
