#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>

namespace texlume {

/// An allocator of arithmetic values whose memory comes zeroed from calloc and
/// whose value-initialisation writes nothing. A large vector of zeros then costs no
/// pass over memory: the kernel zeroes each page when it is first written, by the
/// thread that writes it (a fit's output, written band by band while photos are
/// decoded, instead of one thread's memset before the first photo).
///
/// Value-initialised elements are zero only in memory fresh from allocate(): grow
/// such a vector only from empty (release the old buffer first, as
/// ptm::Ptm::Resize does), never back into capacity it once used.
template <typename T>
struct ZeroedAllocator {
  static_assert(std::is_arithmetic_v<T>, "zero bytes must be the value zero");
  using value_type = T;

  ZeroedAllocator() = default;
  template <typename U>
  explicit ZeroedAllocator(const ZeroedAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n == 0) return nullptr;
    void* memory = std::calloc(n, sizeof(T));
    if (!memory) throw std::bad_alloc();
    return static_cast<T*>(memory);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }

  /// Value-initialisation: the memory is already zero.
  template <typename U>
  void construct(U*) noexcept {}
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  template <typename U>
  bool operator==(const ZeroedAllocator<U>&) const noexcept {
    return true;
  }
};

}  // namespace texlume
