#pragma once

#include <OpenImageIO/filesystem.h>

#include <algorithm>
#include <cstdint>
#include <string_view>

namespace texlume {

/// OpenImageIO's memory reader, reading nothing outside its buffer as a file would.
/// OpenImageIO 2.4's own copies from before its buffer when a reader asks for a
/// negative offset (a damaged EXR chunk table; found by fuzzing,
/// fuzz/regressions/ptm_exr/crash-*).
class BoundedMemoryReader final : public OIIO::Filesystem::IOMemReader {
 public:
  explicit BoundedMemoryReader(std::string_view bytes) : IOMemReader(bytes.data(), bytes.size()) {}
  bool seek(std::int64_t offset) override {
    if (offset < 0) return false;
    m_pos = offset;
    return true;
  }
  std::size_t read(void* buffer, std::size_t bytes) override {
    const std::size_t got = pread(buffer, bytes, m_pos);
    m_pos += static_cast<std::int64_t>(got);
    return got;
  }
  std::size_t pread(void* buffer, std::size_t bytes, std::int64_t offset) override {
    if (offset < 0 || static_cast<std::uint64_t>(offset) >= size()) return 0;
    return IOMemReader::pread(buffer, std::min<std::uint64_t>(bytes, size() - offset), offset);
  }
};

}  // namespace texlume
