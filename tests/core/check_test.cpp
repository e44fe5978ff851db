#include "core/check.h"

#include <gtest/gtest.h>

#include <string>

#include "core/errors.h"

namespace texlume {
namespace {

TEST(Check, ABrokenInvariantIsAnInternalErrorNamingItsPlace) {
  EXPECT_NO_THROW(TEXLUME_CHECK(1 + 1 == 2, "arithmetic"));
  try {
    TEXLUME_CHECK(1 + 1 == 3, "arithmetic holds");
    FAIL() << "no error";
  } catch (const InternalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("check_test.cpp:"), std::string::npos) << what;
    EXPECT_NE(what.find("arithmetic holds"), std::string::npos) << what;
    EXPECT_NE(what.find("1 + 1 == 3"), std::string::npos) << what;
  }
  // Never mistaken for a bad command line or bad input.
  bool option_error = false, input_error = false;
  try {
    TEXLUME_CHECK(false, "x");
  } catch (const OptionError&) {
    option_error = true;
  } catch (const InputError&) {
    input_error = true;
  } catch (const InternalError&) {
  }
  EXPECT_FALSE(option_error);
  EXPECT_FALSE(input_error);
}

}  // namespace
}  // namespace texlume
