#include "apps/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace texlume::apps {

ProgressBar::ProgressBar(std::chrono::milliseconds max_silence)
    : terminal_(::isatty(STDERR_FILENO) == 1),
      max_silence_(max_silence),
      start_(Clock::now()),
      stage_start_(start_),
      last_line_(start_),
      watcher_([this] { Watch(); }) {}

ProgressBar::~ProgressBar() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    if (line_open_) std::fprintf(stderr, "\n");
  }
  stop_signal_.notify_all();
  watcher_.join();
}

void ProgressBar::Update(std::string_view stage, std::size_t done, std::size_t total) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = Clock::now();
  const bool new_stage = stage != stage_;
  const bool restarted = !new_stage && done < done_;
  if (new_stage) {
    if (line_open_) std::fprintf(stderr, "\n");
    line_open_ = false;
    stage_ = std::string(stage);
    stage_start_ = now;
  } else if (terminal_ && !line_open_ && restarted && total_ != 1) {
    std::fprintf(stderr, "\033[A");  // the stage restarts (packing): back onto its finished bar
  }
  done_ = done;
  total_ = total;
  // Terminal: a closed line (a finished bar, an announced step) is not drawn again until
  // its stage restarts.
  if (terminal_ && !new_stage && !line_open_ && !restarted) return;
  // Piped: a stage's first and last updates, and one line at most every max_silence_ between.
  if (terminal_ || new_stage || done >= total || now - last_line_ >= max_silence_) Draw(now, false);
}

// One line (piped) or the bar redrawn (terminal); mutex_ held.
void ProgressBar::Draw(Clock::time_point now, bool heartbeat) {
  const double fraction =
      total_ ? std::min(1.0, static_cast<double>(done_) / static_cast<double>(total_)) : 1.0;
  const double in_stage = std::chrono::duration<double>(now - stage_start_).count();
  const double in_all = std::chrono::duration<double>(now - start_).count();
  const double left = fraction > 0.0 ? in_stage * (1.0 - fraction) / fraction : 0.0;
  if (terminal_ && total_ == 1 && done_ == 0) {
    // A step announced without progress of its own (AnnounceStep): a line of its own.
    std::fprintf(stderr, "\r%s... (%.0fs in all)\n", stage_.c_str(), in_all);
    line_open_ = false;
  } else if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::fprintf(stderr, "\r%-16s [%s%s] %3d%% %zu/%zu  %.1fs left, %.0fs in all ", stage_.c_str(),
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(),
                 static_cast<int>(fraction * 100.0), done_, total_, left, in_all);
    // A finished bar ends its line, so that the job's own output starts on a new one.
    line_open_ = done_ < total_;
    if (!line_open_) std::fprintf(stderr, "\n");
  } else if (heartbeat && stage_.empty()) {
    std::fprintf(stderr, "starting: %.1f s in all\n", in_all);
  } else if (heartbeat && done_ >= total_) {
    std::fprintf(stderr, "after %s: still working, %.1f s in all\n", stage_.c_str(), in_all);
  } else if (heartbeat) {
    std::fprintf(stderr,
                 "%s: %zu/%zu (%.0f%%), still working: %.1f s in this step, %.1f s in all\n",
                 stage_.c_str(), done_, total_, fraction * 100.0, in_stage, in_all);
  } else {
    std::fprintf(stderr, "%s: %zu/%zu (%.0f%%), %.1f s elapsed, %.1f s left, %.1f s in all\n",
                 stage_.c_str(), done_, total_, fraction * 100.0, in_stage, left, in_all);
  }
  last_line_ = now;
  std::fflush(stderr);
}

// A piped log silent for max_silence_ gets a line; a terminal bar its times.
void ProgressBar::Watch() {
  const auto period = max_silence_ / 8;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_signal_.wait_for(lock, period, [this] { return stop_; })) {
    const auto now = Clock::now();
    if (terminal_ ? line_open_ : now - last_line_ >= max_silence_) Draw(now, true);
  }
}

ProgressCallback ProgressBar::Callback() {
  return [this](std::string_view stage, std::size_t done, std::size_t total) {
    Update(stage, done, total);
  };
}

}  // namespace texlume::apps
