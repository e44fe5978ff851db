#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>

#include "core/progress.h"

namespace texlume::apps {

/// Draws progress on stderr: a bar with the estimated time left on a terminal,
/// plain lines at most every few seconds otherwise (logs, CI).
class ProgressBar {
 public:
  ProgressBar();
  void Update(std::string_view stage, std::size_t done, std::size_t total);
  /// A callback for library functions that forwards to Update.
  ProgressCallback Callback();

 private:
  bool terminal_;
  std::string stage_;
  std::chrono::steady_clock::time_point stage_start_;
  std::chrono::steady_clock::time_point last_line_;
};

}  // namespace texlume::apps
