#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "core/check.h"

namespace texlume {

/// Values appended as their bytes, for the messages between the ranks of one
/// job (the same build on every rank: native byte order). Read back with ByteReader.
class ByteWriter {
 public:
  template <typename T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    Append(&value, sizeof(T));
  }
  template <typename T>
  void PutVector(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    Put<std::uint64_t>(values.size());
    Append(values.data(), values.size() * sizeof(T));
  }
  /// A matrix's type, size and elements (empty matrices included).
  void PutString(const std::string& text) {
    PutVector(std::vector<char>(text.begin(), text.end()));
  }
  void PutMat(const cv::Mat& mat) {
    Put<std::int32_t>(mat.type());
    Put<std::int32_t>(mat.rows);
    Put<std::int32_t>(mat.cols);
    if (mat.empty()) return;
    const cv::Mat dense = mat.isContinuous() ? mat : mat.clone();
    Append(dense.data, dense.total() * dense.elemSize());
  }
  void PutMats(const std::vector<cv::Mat>& mats) {
    Put<std::uint64_t>(mats.size());
    for (const cv::Mat& mat : mats) PutMat(mat);
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  void Append(const void* data, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, data, n);
  }
  std::vector<char> bytes_;
};

/// Reads what a ByteWriter wrote, in the same order; every read is checked
/// against the bytes left (InternalError: the ranks disagree).
class ByteReader {
 public:
  explicit ByteReader(const std::vector<char>& bytes) : bytes_(bytes) {}
  explicit ByteReader(std::vector<char>&&) = delete;  // the reader keeps a reference

  template <typename T>
  T Get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, Take(sizeof(T)), sizeof(T));
    return value;
  }
  template <typename T>
  std::vector<T> GetVector() {
    const auto n = Get<std::uint64_t>();
    TEXLUME_CHECK(n <= Remaining() / std::max<std::size_t>(1, sizeof(T)),
                  "a message's vector fits it");
    std::vector<T> values(static_cast<std::size_t>(n));
    if (n) std::memcpy(values.data(), Take(values.size() * sizeof(T)), values.size() * sizeof(T));
    return values;
  }
  std::string GetString() {
    const std::vector<char> text = GetVector<char>();
    return {text.begin(), text.end()};
  }
  cv::Mat GetMat() {
    const auto type = Get<std::int32_t>();
    const auto rows = Get<std::int32_t>();
    const auto cols = Get<std::int32_t>();
    TEXLUME_CHECK(rows >= 0 && cols >= 0, "a message's matrix has a size");
    if (rows == 0 || cols == 0) return cv::Mat();
    const std::size_t element = CV_ELEM_SIZE(type);
    TEXLUME_CHECK(static_cast<std::uint64_t>(rows) * static_cast<std::uint64_t>(cols) <=
                      Remaining() / std::max<std::size_t>(1, element),
                  "a message's matrix fits it");
    cv::Mat mat(rows, cols, type);
    std::memcpy(mat.data, Take(mat.total() * element), mat.total() * element);
    return mat;
  }
  std::vector<cv::Mat> GetMats() {
    const auto n = Get<std::uint64_t>();
    TEXLUME_CHECK(n <= Remaining() / 12, "a message's matrices fit it");
    std::vector<cv::Mat> mats;
    for (std::uint64_t i = 0; i < n; ++i) mats.push_back(GetMat());
    return mats;
  }
  std::size_t Remaining() const { return bytes_.size() - offset_; }

 private:
  const char* Take(std::size_t n) {
    TEXLUME_CHECK(n <= Remaining(), "a message holds what its reader reads");
    const char* p = bytes_.data() + offset_;
    offset_ += n;
    return p;
  }
  const std::vector<char>& bytes_;
  std::size_t offset_ = 0;
};

}  // namespace texlume
