#pragma once

#include <compare>
#include <cstdint>
#include <functional>
#include <limits>
#include <ostream>

namespace texlume::sfm {

/// A typed integer id: a CameraId cannot be passed where an ImageId is expected.
/// The value space is the one COLMAP uses for the same id (uint32 for cameras and
/// images, uint64 for 3D points); the largest value means "invalid / none".
template <typename Tag, typename T>
struct StrongId {
  using value_type = T;
  static constexpr T kInvalidValue = std::numeric_limits<T>::max();

  T value = kInvalidValue;

  constexpr StrongId() = default;
  constexpr explicit StrongId(T v) : value(v) {}
  constexpr bool IsValid() const { return value != kInvalidValue; }
  static constexpr StrongId Invalid() { return StrongId(); }
  auto operator<=>(const StrongId&) const = default;
};

template <typename Tag, typename T>
std::ostream& operator<<(std::ostream& os, const StrongId<Tag, T>& id) {
  return id.IsValid() ? os << id.value : os << "none";
}

using CameraId = StrongId<struct CameraIdTag, std::uint32_t>;
using ImageId = StrongId<struct ImageIdTag, std::uint32_t>;
using Point3DId = StrongId<struct Point3DIdTag, std::uint64_t>;

}  // namespace texlume::sfm

template <typename Tag, typename T>
struct std::hash<texlume::sfm::StrongId<Tag, T>> {
  std::size_t operator()(const texlume::sfm::StrongId<Tag, T>& id) const noexcept {
    return std::hash<T>()(id.value);
  }
};
