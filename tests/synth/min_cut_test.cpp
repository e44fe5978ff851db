#include "synth/min_cut.h"

#include <gtest/gtest.h>

namespace texlume::synth {
namespace {

// A chain a - b - c: a prefers A, c prefers B; the cheapest link is cut.
TEST(MinCut, CutsTheCheapestLinkOfAChain) {
  MinCut cut(3, 2);
  cut.Link(0, 1, 5.0);
  cut.Link(1, 2, 2.0);
  cut.Terminals(0, 0.0, 100.0);
  cut.Terminals(1, 1.0, 1.0);
  cut.Terminals(2, 100.0, 0.0);
  EXPECT_DOUBLE_EQ(cut.Solve(), 1.0 + 2.0);  // node b's own cost plus the cut link
  EXPECT_TRUE(cut.IsA(0));
  EXPECT_TRUE(cut.IsA(1));
  EXPECT_FALSE(cut.IsA(2));
}

// Without links every node takes its cheaper label, and the cost is their sum.
TEST(MinCut, UnlinkedNodesTakeTheirCheaperLabel) {
  MinCut cut(4, 0);
  const double cost_a[4] = {1, 5, 2, 7}, cost_b[4] = {3, 4, 9, 6};
  for (int i = 0; i < 4; ++i) cut.Terminals(i, cost_a[i], cost_b[i]);
  EXPECT_DOUBLE_EQ(cut.Solve(), 1 + 4 + 2 + 6);
  EXPECT_TRUE(cut.IsA(0));
  EXPECT_FALSE(cut.IsA(1));
  EXPECT_TRUE(cut.IsA(2));
  EXPECT_FALSE(cut.IsA(3));
}

}  // namespace
}  // namespace texlume::synth
