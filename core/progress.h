#pragma once

#include <cstddef>
#include <functional>
#include <string_view>

namespace texlume {

/// Reports progress of a long step: `done` of `total` units of the named stage.
/// Called from the calling thread only, a bounded number of times per step;
/// the program draws the bar (library code never prints).
using ProgressCallback =
    std::function<void(std::string_view stage, std::size_t done, std::size_t total)>;

/// Names a step that reports no progress of its own ("writing the model folder"), so
/// that a progress display says what runs: `progress(step, 0, 1)` when set.
inline void AnnounceStep(const ProgressCallback& progress, std::string_view step) {
  if (progress) progress(step, 0, 1);
}

}  // namespace texlume
