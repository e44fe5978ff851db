#include "apps/progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace texlume::apps {

ProgressBar::ProgressBar() : terminal_(::isatty(STDERR_FILENO) == 1) {}

void ProgressBar::Update(std::string_view stage, std::size_t done, std::size_t total) {
  const auto now = std::chrono::steady_clock::now();
  if (stage != stage_) {
    stage_ = std::string(stage);
    stage_start_ = now;
    last_line_ = now - std::chrono::hours(1);
  }
  const double fraction =
      total ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total)) : 1.0;
  const double elapsed = std::chrono::duration<double>(now - stage_start_).count();
  const double left = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  if (terminal_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::fprintf(stderr, "\r%-12s [%s%s] %3d%% %zu/%zu  %.1fs left ", stage_.c_str(),
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(),
                 static_cast<int>(fraction * 100.0), done, total, left);
    if (done >= total) std::fprintf(stderr, "\n");
  } else if (done >= total || now - last_line_ > std::chrono::seconds(5)) {
    std::fprintf(stderr, "%s: %zu/%zu (%.0f%%), %.1f s elapsed, %.1f s left\n", stage_.c_str(),
                 done, total, fraction * 100.0, elapsed, left);
    last_line_ = now;
  }
  std::fflush(stderr);
}

ProgressCallback ProgressBar::Callback() {
  return [this](std::string_view stage, std::size_t done, std::size_t total) {
    Update(stage, done, total);
  };
}

}  // namespace texlume::apps
