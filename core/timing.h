#pragma once

#include <chrono>

namespace texlume {

/// Seconds of wall-clock time since `start` (steady clock).
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace texlume
