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

/// Part `part` (0-based) of `parts` passes of one stage, reported as one count over the
/// whole stage (a thousand units per pass), so that a stage run as several passes draws
/// one bar that only grows. Empty when `progress` is.
inline ProgressCallback PartOfStage(const ProgressCallback& progress, std::size_t part,
                                    std::size_t parts) {
  if (!progress) return {};
  return [progress, part, parts](std::string_view stage, std::size_t done, std::size_t total) {
    constexpr std::size_t kPerPart = 1000;
    const std::size_t within = total > 0 ? (done < total ? done : total) * kPerPart / total : 0;
    progress(stage, part * kPerPart + within, parts * kPerPart);
  };
}

}  // namespace texlume
