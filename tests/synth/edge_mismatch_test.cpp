// The tally behind synth::MeasureEdgeMismatch: point-weighted means and the
// standard error of a class of edges.
#include <gtest/gtest.h>

#include <cmath>

#include "synth/mesh_synthesis.h"

namespace texlume::synth {
namespace {

TEST(EdgeTally, MeanIsWeightedByPointsAndStandardErrorByEdges) {
  EdgeTally t;
  EXPECT_EQ(t.Mean(), 0.0);
  // An edge whose 2 points average 1: one edge has no spread to measure.
  t.Add(2.0, 2);
  EXPECT_EQ(t.StandardError(), 0.0);
  // An edge whose points average 3, and one with no point measured (counted,
  // not averaged).
  t.Add(9.0, 3);
  t.Add(0.0, 0);
  EXPECT_EQ(t.Edges(), 3u);
  EXPECT_DOUBLE_EQ(t.Mean(), 11.0 / 5.0);
  // Edge means 1 and 3: sample variance 2, over 2 edges.
  EXPECT_DOUBLE_EQ(t.StandardError(), std::sqrt(2.0 / 2.0));
}

TEST(EdgeTally, StandardErrorShrinksWithTheSquareRootOfTheEdges) {
  EdgeTally few, many;
  for (int i = 0; i < 100; ++i) few.Add(i % 2 ? 3.0 : 1.0, 1);
  for (int i = 0; i < 400; ++i) many.Add(i % 2 ? 3.0 : 1.0, 1);
  EXPECT_DOUBLE_EQ(few.Mean(), 2.0);
  EXPECT_DOUBLE_EQ(many.Mean(), 2.0);
  EXPECT_NEAR(few.StandardError() / many.StandardError(), 2.0, 0.01);
}

}  // namespace
}  // namespace texlume::synth
