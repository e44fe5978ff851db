#include "ptm/image_bands.h"

#include <omp.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <string>
#include <type_traits>

#include "core/errors.h"
#include "core/first_exception.h"

namespace texlume::ptm {

ImageBands::ImageBands(const std::vector<std::filesystem::path>& files, int threads) {
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
  // As many as OpenMP's team (OMP_NUM_THREADS, else one per hardware thread).
  threads_ = std::max(1, threads > 0 ? threads : omp_get_max_threads());
}

bool ImageBands::eight_bit() const {
  return std::all_of(inputs_.begin(), inputs_.end(),
                     [](const ImageReader& in) { return in.eight_bit(); });
}

namespace {

// Image `input`'s rows [y0, y0 + rows) as rows of R, G and B values
// (BandLayout::kRowPlanar): decoded interleaved into `scratch`, then split row by row.
template <typename Sample>
void ReadRowPlanar(ImageReader& input, int y0, int rows, std::vector<Sample>& scratch,
                   Sample* out) {
  const int plane_type = std::is_same_v<Sample, float> ? CV_32FC1 : CV_8UC1;
  const int type = std::is_same_v<Sample, float> ? CV_32FC3 : CV_8UC3;
  const int width = input.width();
  input.ReadRows(y0, y0 + rows, 3, scratch.data());
  for (int y = 0; y < rows; ++y) {
    Sample* row = out + static_cast<std::size_t>(y) * 3 * static_cast<std::size_t>(width);
    cv::Mat split[3];
    for (std::size_t ch = 0; ch < 3; ++ch)
      split[ch] = cv::Mat(1, width, plane_type, row + ch * static_cast<std::size_t>(width));
    cv::split(
        cv::Mat(1, width, type,
                scratch.data() + static_cast<std::size_t>(y) * 3 * static_cast<std::size_t>(width)),
        split);
  }
}

// ImageBands::ForEach's loop: two bands of every image, the next one read by one
// task per image while tasks of a few rows each process the current one.
template <typename Sample>
class BandPipeline {
 public:
  using Process = std::function<void(const std::vector<const Sample*>&, int, int)>;

  // `threads`: the most threads the team running the tasks may have.
  BandPipeline(std::vector<ImageReader>& inputs, int height, int band_rows, BandLayout layout,
               int threads)
      : inputs_(inputs),
        height_(height),
        band_rows_(band_rows),
        layout_(layout),
        scratch_(static_cast<std::size_t>(threads)) {
    const int width = inputs.empty() ? 0 : inputs[0].width();
    row_samples_ = static_cast<std::size_t>(width) * 3;
    // Rows per process task: at least 4096 pixels, so that a task outweighs its cost.
    task_rows_ = std::max(1, (4096 + width - 1) / std::max(1, width));
    for (auto& set : bands_)
      set.assign(inputs.size(),
                 std::vector<Sample>(static_cast<std::size_t>(band_rows) * row_samples_));
  }

  // Runs on the calling thread, the primary thread of an OpenMP team whose threads
  // run the tasks (so that `progress` is called from the calling thread).
  void Run(const Process& process, const ProgressCallback& progress, const char* stage) {
    if (height_ > 0) SpawnReads(0, bands_[0]);
#pragma omp taskwait
    for (int b = 0, y0 = 0; y0 < height_ && !error_.Failed(); ++b, y0 += band_rows_) {
      if (y0 + band_rows_ < height_) SpawnReads(y0 + band_rows_, bands_[(b + 1) % 2]);
      SpawnProcess(process, bands_[b % 2], y0);
#pragma omp taskwait
      const int done = std::min(height_, y0 + band_rows_);
      if (progress)
        error_.Run([&] {
          progress(stage, static_cast<std::size_t>(done), static_cast<std::size_t>(height_));
        });
    }
  }

  void Rethrow() { error_.Rethrow(); }

 private:
  // One task per image: its rows [y0, y0 + band_rows) into `band`.
  void SpawnReads(int y0, std::vector<std::vector<Sample>>& band) {
    const int rows = std::min(band_rows_, height_ - y0);
    for (std::size_t k = 0; k < inputs_.size(); ++k) {
#pragma omp task firstprivate(k, y0, rows) shared(band)
      error_.Run([&] { Read(k, y0, rows, band[k].data()); });
    }
  }

  void Read(std::size_t k, int y0, int rows, Sample* out) {
    if (layout_ == BandLayout::kInterleaved) {
      inputs_[k].ReadRows(y0, y0 + rows, 3, out);
      return;
    }
    // The thread's own scratch (a task stays on its thread): kept for every band.
    std::vector<Sample>& scratch = scratch_[static_cast<std::size_t>(omp_get_thread_num())];
    scratch.resize(static_cast<std::size_t>(band_rows_) * row_samples_);
    ReadRowPlanar(inputs_[k], y0, rows, scratch, out);
  }

  // Tasks of task_rows_ rows each over the band starting at row y0.
  void SpawnProcess(const Process& process, const std::vector<std::vector<Sample>>& band, int y0) {
    const int rows = std::min(band_rows_, height_ - y0);
    for (int r0 = 0; r0 < rows; r0 += task_rows_) {
      const int count = std::min(task_rows_, rows - r0);
#pragma omp task firstprivate(r0, y0, count) shared(band, process)
      error_.Run([&] {
        std::vector<const Sample*> pixels;
        for (const auto& image_band : band)
          pixels.push_back(image_band.data() + static_cast<std::size_t>(r0) * row_samples_);
        process(pixels, y0 + r0, count);
      });
    }
  }

  std::vector<ImageReader>& inputs_;
  int height_, band_rows_;
  BandLayout layout_;
  std::size_t row_samples_ = 0;
  int task_rows_ = 1;
  std::vector<std::vector<Sample>> scratch_;  // one per thread of the team
  std::vector<std::vector<Sample>> bands_[2];
  FirstException error_;
};

}  // namespace

template <typename Sample>
void ImageBands::ForEach(
    int band_rows,
    const std::function<void(const std::vector<const Sample*>& pixels, int y0, int rows)>& process,
    const ProgressCallback& progress, const char* stage, BandLayout layout) {
  BandPipeline<Sample> pipeline(inputs_, height_, band_rows, layout, threads_);
#pragma omp parallel num_threads(threads_)
#pragma omp masked
  pipeline.Run(process, progress, stage);  // the others run tasks at the region's barrier
  pipeline.Rethrow();
}

template void ImageBands::ForEach<float>(
    int, const std::function<void(const std::vector<const float*>&, int, int)>&,
    const ProgressCallback&, const char*, BandLayout);
template void ImageBands::ForEach<std::uint8_t>(
    int, const std::function<void(const std::vector<const std::uint8_t*>&, int, int)>&,
    const ProgressCallback&, const char*, BandLayout);

}  // namespace texlume::ptm
