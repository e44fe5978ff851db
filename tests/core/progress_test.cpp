#include "core/progress.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace texlume {
namespace {

// Three passes of different lengths report one count that only grows, from the
// first pass's start to the whole stage at the last pass's end.
TEST(PartOfStage, PassesOfOneStageMakeOneGrowingCount) {
  std::vector<std::pair<std::size_t, std::size_t>> seen;
  const ProgressCallback progress = [&](std::string_view stage, std::size_t done,
                                        std::size_t total) {
    EXPECT_EQ(stage, "packing strips");
    seen.emplace_back(done, total);
  };
  const std::size_t lengths[] = {163, 20, 7};
  for (std::size_t pass = 0; pass < 3; ++pass) {
    const ProgressCallback part = PartOfStage(progress, pass, 3);
    for (std::size_t done = 1; done <= lengths[pass]; ++done)
      part("packing strips", done, lengths[pass]);
  }
  ASSERT_EQ(seen.size(), 163u + 20u + 7u);
  for (std::size_t i = 1; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].second, seen.front().second);
    EXPECT_GT(seen[i].first, seen[i - 1].first);
  }
  EXPECT_EQ(seen.back().first, seen.back().second);
  EXPECT_FALSE(PartOfStage({}, 0, 3));
}

}  // namespace
}  // namespace texlume
