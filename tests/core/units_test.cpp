#include "core/units.h"

#include <gtest/gtest.h>

#include "core/errors.h"

namespace texlume {
namespace {

TEST(ParseLengthMm, ReadsEachUnit) {
  EXPECT_DOUBLE_EQ(ParseLengthMm("1m", "--world-unit"), 1000.0);
  EXPECT_DOUBLE_EQ(ParseLengthMm("2.5 cm", "--world-unit"), 25.0);
  EXPECT_DOUBLE_EQ(ParseLengthMm("25.4mm", "--world-unit"), 25.4);
  EXPECT_DOUBLE_EQ(ParseLengthMm("1in", "--world-unit"), 25.4);
  EXPECT_DOUBLE_EQ(ParseLengthMm("2ft", "--world-unit"), 609.6);
  EXPECT_DOUBLE_EQ(ParseLengthMm("500um", "--world-unit"), 0.5);
  EXPECT_DOUBLE_EQ(ParseLengthMm("500\u00b5m", "--world-unit"), 0.5);
  EXPECT_DOUBLE_EQ(ParseLengthMm("m", "--world-unit"), 1000.0);
  EXPECT_DOUBLE_EQ(ParseLengthMm(".5m", "--world-unit"), 500.0);
}

TEST(ParseLengthMm, RefusesWhatIsNotALengthNamingTheOption) {
  for (const char* bad :
       {"", "1", "1 parsec", "-1m", "0m", "1e30m", "nanm", "m1", "1M", "x", "0x10mm", "infm"}) {
    try {
      ParseLengthMm(bad, "--world-unit");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find("--world-unit"), std::string::npos) << e.what();
    }
  }
}

TEST(LengthText, ChoosesTheUnitThatReadsBest) {
  EXPECT_EQ(MillimetreText(0.0391), "39.1 um");
  EXPECT_EQ(MillimetreText(3.912), "3.91 mm");
  EXPECT_EQ(MillimetreText(1200.0), "1.2 m");
  EXPECT_EQ(WorldLengthText(0.00391, 0.0), "0.00391 world units");
  EXPECT_EQ(WorldLengthText(0.00391, 1000.0), "0.00391 world units (3.91 mm)");
  // Never an exponent: lengths that round up take the next unit, large ones all digits.
  EXPECT_EQ(MillimetreText(999.7), "1 m");
  EXPECT_EQ(MillimetreText(0.09996), "0.1 mm");
  EXPECT_EQ(WorldLengthText(1234.0, 0.0), "1230 world units");
  EXPECT_EQ(ThreeSignificantDigits(999.7), "1000");
  EXPECT_EQ(ThreeSignificantDigits(-0.012345), "-0.0123");
}

TEST(NiceLengthAtMost, IsOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(7.3), 5.0);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(3.9), 2.0);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(1.7), 1.0);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(0.02), 0.02);
  EXPECT_NEAR(NiceLengthAtMost(0.0049), 0.002, 1e-15);
  EXPECT_DOUBLE_EQ(NiceLengthAtMost(100.0), 100.0);
  EXPECT_EQ(NiceLengthAtMost(0.0), 0.0);
}

}  // namespace
}  // namespace texlume
