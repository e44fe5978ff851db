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
const std::uint64_t kPhotoBytes = 3 * 16 * 8;  // 8-bit RGB as stored

TEST(PhotoCache, KeepsTheMostRecentlyUsedPhotosWithinItsBudget) {
  TempDir tmp;
  PhotoCache cache(2 * kPhotoBytes);  // two photos
  std::vector<std::size_t> keys;
  for (int n = 1; n <= 3; ++n) keys.push_back(cache.Add(WritePhoto(tmp.path(), n), kSize, 3));
  EXPECT_EQ(cache.TotalBytes(), 3 * kPhotoBytes);
  EXPECT_FALSE(cache.HoldsAll());
  // Each photo's own pixels, in RGB order and [0, 1].
  for (int n = 1; n <= 3; ++n) {
    const cv::Mat native = cache.Get(keys[static_cast<std::size_t>(n - 1)]);
    ASSERT_EQ(native.type(), CV_8UC3);
    EXPECT_EQ(native.at<cv::Vec3b>(4, 7), cv::Vec3b(n, 2 * n, 3 * n));
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
  const std::size_t a = cache.Add(WritePhoto(tmp.path(), 10), kSize, 3);
  const std::size_t b = cache.Add(WritePhoto(tmp.path(), 20), kSize, 3);
  const cv::Mat held = cache.Get(a);
  cache.Get(b);  // the cache lets `a` go
  EXPECT_EQ(held.at<cv::Vec3b>(0, 0)[0], 10);
  cache.Get(a);
  EXPECT_EQ(cache.stats().decodes, 3u);
}

TEST(PhotoCache, APhotoAskedForByManyThreadsAtOnceIsDecodedOnce) {
  TempDir tmp;
  PhotoCache cache(4 * kPhotoBytes);
  const std::size_t key = cache.Add(WritePhoto(tmp.path(), 7), kSize, 3);
  std::vector<std::thread> threads;
  std::vector<float> red(8, 0.0f);
  for (std::size_t i = 0; i < red.size(); ++i)
    threads.emplace_back([&, i] { red[i] = cache.Get(key).at<cv::Vec3b>(1, 1)[0]; });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(cache.stats().decodes, 1u);
  EXPECT_EQ(cache.stats().hits, 7u);
  for (const float r : red) EXPECT_EQ(r, 7.0f);
}

TEST(PhotoCache, AFileThatCannotBeDecodedOrChangedSizeIsNamed) {
  TempDir tmp;
  PhotoCache cache(4 * kPhotoBytes);
  const fs::path broken = tmp.path() / "broken.png";
  std::ofstream(broken) << "not a png";
  const std::size_t bad = cache.Add(broken, kSize, 3);
  const std::size_t resized = cache.Add(WritePhoto(tmp.path(), 1), cv::Size(32, 8), 3);
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
  EXPECT_EQ(pixels.Display().data, image.data);
  EXPECT_EQ(pixels.Held().data, image.data);
  EXPECT_EQ(pixels.cache(), nullptr);
}

// A region of a cached photo reads as the same region of ReadPhotoRgb's photo, at
// every depth a photo may be stored in, cut to the photo at its borders.
TEST(PhotoPixels, RegionsOfACachedPhotoAreThePhotosDisplayValues) {
  TempDir tmp;
  cv::Mat bgr8(12, 20, CV_8UC3), grey16(12, 20, CV_16UC1);
  cv::randu(bgr8, 0, 256);
  cv::randu(grey16, 0, 65536);
  const fs::path png8 = tmp.path() / "rgb8.png", png16 = tmp.path() / "grey16.png";
  ASSERT_TRUE(cv::imwrite(png8.string(), bgr8));
  ASSERT_TRUE(cv::imwrite(png16.string(), grey16));
  auto cache = std::make_shared<PhotoCache>(std::uint64_t{1} << 20);
  for (const fs::path& file : {png8, png16}) {
    const PhotoPixels pixels(cache, cache->Add(file, cv::Size(20, 12), 12));
    const cv::Mat whole = ReadPhotoRgb(file);
    ASSERT_EQ(pixels.Display().type(), CV_32FC3);
    EXPECT_EQ(cv::norm(pixels.Display(), whole, cv::NORM_INF), 0.0) << file;
    const cv::Mat region = pixels.Display(cv::Rect(15, 8, 10, 10));  // cut to 5 x 4
    ASSERT_EQ(region.size(), cv::Size(5, 4));
    EXPECT_EQ(cv::norm(region, whole(cv::Rect(15, 8, 5, 4)), cv::NORM_INF), 0.0) << file;
  }
  EXPECT_EQ(cache->stats().decodes, 2u);
  EXPECT_EQ(cache->stats().peak_bytes, 20u * 12 * 3 + 20u * 12 * 6);  // as stored
}

}  // namespace
}  // namespace texlume
