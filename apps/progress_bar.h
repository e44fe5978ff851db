#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

#include "core/progress.h"

namespace texlume::apps {

/// Draws progress on stderr: a bar with the estimated time left on a terminal,
/// plain lines at most every few seconds otherwise (logs, CI). Every line gives the
/// time since the bar was made (the whole command). A finished bar ends its line; a
/// stage that restarts (packing tries several atlas sizes) redraws its bar in place.
/// A watcher thread makes sure a piped
/// log never stays silent for more than 4.5 s: while no update comes, it repeats the
/// current stage with the time spent in it.
class ProgressBar {
 public:
  /// `max_silence`: a piped log gets a line once it has been silent this long, checked
  /// every max_silence / 8, so no gap exceeds 4.5 s by default (tests shorten it).
  explicit ProgressBar(std::chrono::milliseconds max_silence = std::chrono::seconds(4));
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void Update(std::string_view stage, std::size_t done, std::size_t total);
  /// A callback for library functions that forwards to Update.
  ProgressCallback Callback();

 private:
  using Clock = std::chrono::steady_clock;
  void Draw(Clock::time_point now, bool heartbeat);
  void Watch();

  const bool terminal_;
  const std::chrono::milliseconds max_silence_;
  const Clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable stop_signal_;
  bool stop_ = false;
  bool line_open_ = false;  // a terminal bar is drawn without its newline
  std::string stage_;
  std::size_t done_ = 0, total_ = 0;
  Clock::time_point stage_start_, last_line_;
  std::thread watcher_;
};

}  // namespace texlume::apps
