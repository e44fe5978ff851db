// Progress as a piped log shows it (ctest's stderr is not a terminal): a line at each
// stage's start and end, and never a silence longer than the limit.
#include "apps/progress_bar.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <thread>

namespace texlume::apps {
namespace {

using namespace std::chrono_literals;

TEST(ProgressBar, APipedLogIsNeverSilentLongerThanTheLimitAndGivesTheTotalTime) {
  ASSERT_FALSE(::isatty(STDERR_FILENO)) << "run with stderr piped";
  ::testing::internal::CaptureStderr();
  {
    ProgressBar bar(400ms);
    bar.Update("synthesis", 0, 10);
    bar.Update("synthesis", 5, 10);   // within the limit of the last line: not printed
    std::this_thread::sleep_for(1s);  // the step works without reporting
    bar.Update("synthesis", 10, 10);
    std::this_thread::sleep_for(1s);  // unnamed work after the stage ended
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("synthesis: 0/10 (0%)"), std::string::npos) << log;
  EXPECT_EQ(log.find("synthesis: 5/10 (50%), 0.0 s"), std::string::npos) << log;
  EXPECT_NE(log.find("synthesis: 5/10 (50%), still working"), std::string::npos) << log;
  EXPECT_NE(log.find("synthesis: 10/10 (100%)"), std::string::npos) << log;
  EXPECT_NE(log.find("after synthesis: still working"), std::string::npos) << log;
  EXPECT_NE(log.find("s in all"), std::string::npos) << log;
}

}  // namespace
}  // namespace texlume::apps
