#include "core/photo_cache.h"

#include <chrono>
#include <string>

#include "core/check.h"
#include "core/errors.h"
#include "core/image_io.h"
#include "core/timing.h"

namespace texlume {

std::uint64_t DecodedPhotoBytes(cv::Size size, int bytes_per_pixel) {
  return static_cast<std::uint64_t>(std::max(0, bytes_per_pixel)) *
         static_cast<std::uint64_t>(std::max(0, size.width)) *
         static_cast<std::uint64_t>(std::max(0, size.height));
}

PhotoCache::PhotoCache(std::uint64_t budget_bytes) : budget_bytes_(budget_bytes) {}

std::size_t PhotoCache::Add(std::filesystem::path file, cv::Size size, int bytes_per_pixel) {
  std::lock_guard lock(mutex_);
  Entry entry;
  entry.file = std::move(file);
  entry.size = size;
  entry.bytes = DecodedPhotoBytes(size, bytes_per_pixel);
  entries_.push_back(std::move(entry));
  return entries_.size() - 1;
}

namespace {

// The photo in `file`, checked against the size its header gave.
cv::Mat DecodePhoto(const std::filesystem::path& file, cv::Size size) {
  cv::Mat image = ReadPhotoNative(file);
  if (image.size() != size)
    throw InputError(file.string(),
                     "decodes to " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                         " pixels, but its header said " + std::to_string(size.width) + "x" +
                         std::to_string(size.height));
  return image;
}

}  // namespace

cv::Mat PhotoCache::Get(std::size_t key) {
  std::unique_lock lock(mutex_);
  TEXLUME_CHECK(key < entries_.size(), "a photo key of the cache");
  decoded_.wait(lock, [&] { return !entries_[key].decoding; });
  Entry& entry = entries_[key];
  if (!entry.image.empty()) {
    ++stats_.hits;
    recent_.splice(recent_.begin(), recent_, entry.recent);
    return entry.image;
  }
  entry.decoding = true;
  const std::filesystem::path file = entry.file;
  const cv::Size size = entry.size;
  lock.unlock();
  const auto start = std::chrono::steady_clock::now();
  cv::Mat image;
  try {
    image = DecodePhoto(file, size);
  } catch (...) {
    lock.lock();
    entries_[key].decoding = false;
    decoded_.notify_all();
    throw;
  }
  lock.lock();
  stats_.seconds_decoding += SecondsSince(start);
  entries_[key].decoding = false;
  Hold(key, image);
  decoded_.notify_all();
  return image;
}

void PhotoCache::Hold(std::size_t key, cv::Mat image) {
  Entry& entry = entries_[key];
  entry.image = std::move(image);
  entry.bytes = entry.image.total() * entry.image.elemSize();
  recent_.push_front(key);
  entry.recent = recent_.begin();
  held_bytes_ += entry.bytes;
  ++stats_.decodes;
  LetGoBeyondBudget(key);
  stats_.peak_bytes = std::max(stats_.peak_bytes, held_bytes_);
}

void PhotoCache::LetGoBeyondBudget(std::size_t keep) {
  while (held_bytes_ > budget_bytes_ && recent_.size() > 1) {
    const std::size_t oldest = recent_.back();
    if (oldest == keep) break;
    Entry& entry = entries_[oldest];
    recent_.pop_back();
    entry.image.release();
    held_bytes_ -= entry.bytes;
  }
}

const std::filesystem::path& PhotoCache::File(std::size_t key) const {
  std::lock_guard lock(mutex_);
  TEXLUME_CHECK(key < entries_.size(), "a photo key of the cache");
  return entries_[key].file;
}

cv::Size PhotoCache::Size(std::size_t key) const {
  std::lock_guard lock(mutex_);
  TEXLUME_CHECK(key < entries_.size(), "a photo key of the cache");
  return entries_[key].size;
}

std::size_t PhotoCache::NumPhotos() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::uint64_t PhotoCache::TotalBytes() const {
  std::lock_guard lock(mutex_);
  std::uint64_t total = 0;
  for (const Entry& entry : entries_) total += entry.bytes;
  return total;
}

PhotoCache::Stats PhotoCache::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace texlume
