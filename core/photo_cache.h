#pragma once

#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <vector>

#include "core/image_io.h"

namespace texlume {

/// Bytes a decoded photo of `size` takes at `bytes_per_pixel` (3 for an 8-bit file
/// as ReadPhotoNative keeps it, 12 for float).
std::uint64_t DecodedPhotoBytes(cv::Size size, int bytes_per_pixel);

/// Decoded photos on demand within a budget of bytes (issue 33, "photos on
/// demand"): a photo is decoded by ReadPhotoNative (its stored sample type: 3
/// bytes a pixel for JPEG) when it is asked for and not held, and the least
/// recently used photos are let go while the held ones exceed the budget. A photo handed out stays
/// valid for as long as its holder keeps it (cv::Mat counts its references), so the cache may hold
/// less than the photos in use by up to one photo per thread. Safe to use from several threads; a
/// photo asked for by two threads at once is decoded once.
class PhotoCache {
 public:
  struct Stats {
    std::uint64_t decodes = 0;     ///< photos decoded (a photo let go and asked again counts again)
    std::uint64_t hits = 0;        ///< asks answered from the held photos
    std::uint64_t peak_bytes = 0;  ///< most bytes held at once
    double seconds_decoding = 0.0;
  };

  explicit PhotoCache(std::uint64_t budget_bytes);

  /// Registers a photo file whose size (from its header) is `size` and that will
  /// take about `bytes_per_pixel` decoded (the budget counts the real bytes once
  /// it is); its key. Every photo is registered before the first Get.
  std::size_t Add(std::filesystem::path file, cv::Size size, int bytes_per_pixel);

  /// The photo `key` as ReadPhotoNative gives it, decoded when not held. Throws
  /// InputError naming the file when it cannot be decoded or its decoded size is
  /// not the registered one.
  cv::Mat Get(std::size_t key);

  const std::filesystem::path& File(std::size_t key) const;
  cv::Size Size(std::size_t key) const;
  std::size_t NumPhotos() const;
  std::uint64_t budget_bytes() const { return budget_bytes_; }
  /// Bytes of every registered photo decoded (what holding them all would take;
  /// registered estimates for the photos not decoded yet).
  std::uint64_t TotalBytes() const;
  /// Whether the budget holds every registered photo at once.
  bool HoldsAll() const { return TotalBytes() <= budget_bytes_; }
  Stats stats() const;

 private:
  struct Entry {
    std::filesystem::path file;
    cv::Size size;
    std::uint64_t bytes = 0;  // estimated, then the decoded image's
    cv::Mat image;            // empty while not held
    bool decoding = false;
    std::list<std::size_t>::iterator recent;  // in recent_ while held
  };
  void Hold(std::size_t key, cv::Mat image);  // with mutex_ held
  void LetGoBeyondBudget(std::size_t keep);   // with mutex_ held

  const std::uint64_t budget_bytes_;
  mutable std::mutex mutex_;
  std::condition_variable decoded_;
  std::vector<Entry> entries_;
  std::list<std::size_t> recent_;  // held photos, most recently used first
  std::uint64_t held_bytes_ = 0;
  Stats stats_;
};

/// A photo's pixels: held in memory (tests, photos made in memory) or decoded on
/// demand through a PhotoCache shared by the photos of a job. Read them as
/// display RGB (CV_32FC3 in [0, 1], ReadPhotoRgb's values), whole or a region.
class PhotoPixels {
 public:
  PhotoPixels() = default;
  /// Pixels already in memory (CV_32FC3 display RGB, or as ReadPhotoNative gives).
  explicit PhotoPixels(cv::Mat held) : held_(std::move(held)) {}
  PhotoPixels(std::shared_ptr<PhotoCache> cache, std::size_t key)
      : cache_(std::move(cache)), key_(key) {}

  cv::Size size() const { return cache_ ? cache_->Size(key_) : held_.size(); }
  /// The stored pixels (decoded when not held; see PhotoCache::Get).
  cv::Mat Native() const { return cache_ ? cache_->Get(key_) : held_; }
  /// The whole photo as display RGB.
  cv::Mat Display() const { return PhotoDisplayRgb(Native()); }
  /// The part of the photo inside `region` (cut to the photo) as display RGB.
  cv::Mat Display(cv::Rect region) const {
    const cv::Mat native = Native();
    return PhotoDisplayRgb(native(region & cv::Rect(0, 0, native.cols, native.rows)));
  }
  /// The pixels when they live in memory for good; empty when decoded on demand.
  const cv::Mat& Held() const { return held_; }
  /// The cache the pixels come from (null when held).
  const std::shared_ptr<PhotoCache>& cache() const { return cache_; }

 private:
  cv::Mat held_;
  std::shared_ptr<PhotoCache> cache_;
  std::size_t key_ = 0;
};

}  // namespace texlume
