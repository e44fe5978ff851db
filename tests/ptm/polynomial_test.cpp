#include "ptm/polynomial.h"

#include <gtest/gtest.h>

namespace texlume::ptm {
namespace {

TEST(PtmPolynomial, EvaluationIsTheBasisDotTheCoefficients) {
  const std::array<double, 6> a = {0.5, -0.25, 0.125, 2.0, -1.0, 0.75};
  for (double lu : {-0.7, 0.0, 0.3}) {
    for (double lv : {-0.2, 0.1, 0.9}) {
      const auto basis = PtmBasis(lu, lv);
      double dot = 0;
      for (int i = 0; i < 6; ++i)
        dot += a[static_cast<std::size_t>(i)] * basis[static_cast<std::size_t>(i)];
      EXPECT_DOUBLE_EQ(EvaluatePtm(a, lu, lv), dot);
    }
  }
  // Known answer, paper 003 eq. 1 at (lu, lv) = (0.5, -0.5).
  EXPECT_DOUBLE_EQ(EvaluatePtm(a, 0.5, -0.5),
                   0.5 * 0.25 - 0.25 * 0.25 + 0.125 * -0.25 + 2.0 * 0.5 + -1.0 * -0.5 + 0.75);
}

}  // namespace
}  // namespace texlume::ptm
