#include "ptm/image_bands.h"

#include <gtest/gtest.h>

#include <atomic>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "tests/test_util.h"

namespace texlume::ptm {
namespace {

// Three 8-bit PNGs of random pixels, wide enough (4096) that each band's rows are
// processed by several tasks at once.
struct Capture {
  std::vector<std::filesystem::path> files;
  std::vector<cv::Mat> rgb;  // as read back, RGB order
};

Capture WriteCapture(const std::filesystem::path& dir, int width, int height) {
  Capture c;
  std::mt19937 rng(11);
  for (int k = 0; k < 3; ++k) {
    cv::Mat bgr(height, width, CV_8UC3);
    for (int i = 0; i < bgr.rows * bgr.cols * 3; ++i) bgr.data[i] = rng() & 255;
    c.files.push_back(dir / ("i" + std::to_string(k) + ".png"));
    cv::imwrite(c.files.back().string(), bgr);
    cv::Mat rgb(height, width, CV_8UC3);
    cv::mixChannels(bgr, rgb, {0, 2, 1, 1, 2, 0});
    c.rgb.push_back(rgb);
  }
  return c;
}

TEST(ImageBands, EveryRowIsProcessedOnceWithTheImagesPixelsInEitherLayout) {
  testing::TempDir tmp;
  const Capture c = WriteCapture(tmp.path(), 4096, 23);  // bands of 5: the last one short
  for (const BandLayout layout : {BandLayout::kInterleaved, BandLayout::kRowPlanar}) {
    ImageBands bands(c.files, 2);
    std::vector<std::atomic<int>> visits(23);
    std::atomic<int> wrong{0}, progress_calls{0}, progress_elsewhere{0};
    const std::thread::id caller = std::this_thread::get_id();
    bands.ForEach<std::uint8_t>(
        5,
        [&](const std::vector<const std::uint8_t*>& pixels, int y0, int rows) {
          for (int r = 0; r < rows; ++r) {
            ++visits[static_cast<std::size_t>(y0 + r)];
            for (std::size_t k = 0; k < 3; ++k)
              for (int x = 0; x < 4096; x += 97)
                for (int ch = 0; ch < 3; ++ch) {
                  const std::size_t at = layout == BandLayout::kInterleaved
                                             ? (static_cast<std::size_t>(r) * 4096 + x) * 3 + ch
                                             : (static_cast<std::size_t>(r) * 3 + ch) * 4096 + x;
                  if (pixels[k][at] != c.rgb[k].at<cv::Vec3b>(y0 + r, x)[ch]) ++wrong;
                }
          }
        },
        [&](std::string_view, std::size_t done, std::size_t total) {
          if (std::this_thread::get_id() != caller) ++progress_elsewhere;
          EXPECT_EQ(total, 23u);
          EXPECT_EQ(done,
                    std::min<std::size_t>(23, 5 * static_cast<std::size_t>(++progress_calls)));
        },
        "test", layout);
    for (int y = 0; y < 23; ++y) EXPECT_EQ(visits[static_cast<std::size_t>(y)], 1) << "row " << y;
    EXPECT_EQ(wrong, 0);
    EXPECT_EQ(progress_calls, 5);
    EXPECT_EQ(progress_elsewhere, 0);  // progress comes from the calling thread only
  }
}

TEST(ImageBands, AThrowingCallEndsTheLoopAfterItsBandAndIsRethrown) {
  testing::TempDir tmp;
  const Capture c = WriteCapture(tmp.path(), 4096, 23);
  ImageBands bands(c.files, 2);
  std::atomic<int> last_row{-1};
  EXPECT_THROW(bands.ForEach<std::uint8_t>(
                   5,
                   [&](const std::vector<const std::uint8_t*>&, int y0, int rows) {
                     for (int r = 0; r < rows; ++r) {
                       int seen = last_row.load();
                       while (seen < y0 + r && !last_row.compare_exchange_weak(seen, y0 + r)) {
                       }
                     }
                     if (y0 == 7) throw std::runtime_error("row 7");
                   },
                   {}, "test", BandLayout::kRowPlanar),
               std::runtime_error);
  EXPECT_LT(last_row, 10);  // no row of a band after the one that threw
}

}  // namespace
}  // namespace texlume::ptm
