#include "core/photo_cache.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.h"
#include "tests/test_util.h"

namespace texlume {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;

// A 16 x 8 PNG whose every pixel is (n, 2n, 3n) in 8-bit values.
fs::path WritePhoto(const fs::path& dir, int n) {
  const fs::path file = dir / ("photo_" + std::to_string(n) + ".png");
  const cv::Mat bgr(8, 16, CV_8UC3, cv::Scalar(3 * n, 2 * n, n));
  EXPECT_TRUE(cv::imwrite(file.string(), bgr));
  return file;
}

const cv::Size kSize(16, 8);
const std::uint64_t kPhotoBytes = 12 * 16 * 8;

TEST(PhotoCache, KeepsTheMostRecentlyUsedPhotosWithinItsBudget) {
  TempDir tmp;
  PhotoCache cache(2 * kPhotoBytes);  // two photos
  std::vector<std::size_t> keys;
  for (int n = 1; n <= 3; ++n) keys.push_back(cache.Add(WritePhoto(tmp.path(), n), kSize));
  EXPECT_EQ(cache.TotalBytes(), 3 * kPhotoBytes);
  EXPECT_FALSE(cache.HoldsAll());
  // Each photo's own pixels, in RGB order and [0, 1].
  for (int n = 1; n <= 3; ++n) {
    const cv::Vec3f rgb = cache.Get(keys[static_cast<std::size_t>(n - 1)]).at<cv::Vec3f>(4, 7);
    EXPECT_NEAR(rgb[0], n / 255.0, 1e-6);
    EXPECT_NEAR(rgb[2], 3 * n / 255.0, 1e-6);
  }
  EXPECT_EQ(cache.stats().decodes, 3u);
  // Photos 2 and 3 are held; 1 was let go.
  cache.Get(keys[1]);
  cache.Get(keys[2]);
  EXPECT_EQ(cache.stats().decodes, 3u);
  EXPECT_EQ(cache.stats().hits, 2u);
  cache.Get(keys[0]);  // decoded again; lets go of 2, the least recently used
  EXPECT_EQ(cache.stats().decodes, 4u);
  cache.Get(keys[2]);
  EXPECT_EQ(cache.stats().decodes, 4u);
  cache.Get(keys[1]);
  EXPECT_EQ(cache.stats().decodes, 5u);
  EXPECT_EQ(cache.stats().peak_bytes, 2 * kPhotoBytes);
}

TEST(PhotoCache, APhotoHandedOutStaysValidAfterTheCacheLetsItGo) {
  TempDir tmp;
  PhotoCache cache(kPhotoBytes);
  const std::size_t a = cache.Add(WritePhoto(tmp.path(), 10), kSize);
  const std::size_t b = cache.Add(WritePhoto(tmp.path(), 20), kSize);
  const cv::Mat held = cache.Get(a);
  cache.Get(b);  // the cache lets `a` go
  EXPECT_NEAR(held.at<cv::Vec3f>(0, 0)[0], 10 / 255.0, 1e-6);
  cache.Get(a);
  EXPECT_EQ(cache.stats().decodes, 3u);
}

TEST(PhotoCache, APhotoAskedForByManyThreadsAtOnceIsDecodedOnce) {
  TempDir tmp;
  PhotoCache cache(4 * kPhotoBytes);
  const std::size_t key = cache.Add(WritePhoto(tmp.path(), 7), kSize);
  std::vector<std::thread> threads;
  std::vector<float> red(8, 0.0f);
  for (std::size_t i = 0; i < red.size(); ++i)
    threads.emplace_back([&, i] { red[i] = cache.Get(key).at<cv::Vec3f>(1, 1)[0]; });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(cache.stats().decodes, 1u);
  EXPECT_EQ(cache.stats().hits, 7u);
  for (const float r : red) EXPECT_NEAR(r, 7 / 255.0, 1e-6);
}

TEST(PhotoCache, AFileThatCannotBeDecodedOrChangedSizeIsNamed) {
  TempDir tmp;
  PhotoCache cache(4 * kPhotoBytes);
  const fs::path broken = tmp.path() / "broken.png";
  std::ofstream(broken) << "not a png";
  const std::size_t bad = cache.Add(broken, kSize);
  const std::size_t resized = cache.Add(WritePhoto(tmp.path(), 1), cv::Size(32, 8));
  for (const std::size_t key : {bad, resized}) {
    try {
      cache.Get(key);
      ADD_FAILURE() << "decoded " << cache.File(key);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(cache.File(key).filename().string()), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(cache.stats().decodes, 0u);
  // A failed decode leaves nothing waiting: the next ask tries again.
  EXPECT_THROW(cache.Get(bad), InputError);
}

TEST(PhotoPixels, HeldPixelsNeedNoCache) {
  const cv::Mat image(3, 5, CV_32FC3, cv::Scalar(0.25, 0.5, 0.75));
  const PhotoPixels pixels(image);
  EXPECT_EQ(pixels.size(), cv::Size(5, 3));
  EXPECT_EQ(pixels.Get().data, image.data);
  EXPECT_EQ(pixels.Held().data, image.data);
  EXPECT_EQ(pixels.cache(), nullptr);
}

}  // namespace
}  // namespace texlume
