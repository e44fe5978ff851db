// The fuzz targets' parsers outside the fuzzer (fuzz/fuzz_inputs.h): every seed
// the project generates parses, and every input kept in fuzz/regressions (each
// an earlier finding) is now parsed or refused with an InputError, nothing else.
#include "fuzz/fuzz_inputs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "core/errors.h"
#include "fuzz/fuzz_seeds.h"
#include "tests/test_util.h"

namespace texlume::fuzz {
namespace {

namespace fs = std::filesystem;

TEST(FuzzInputs, EverySeedOfEveryTargetParses) {
  testing::TempDir tmp;
  WriteFuzzSeeds(tmp.path());
  for (const std::string& target : Targets()) {
    std::size_t seeds = 0;
    for (const auto& entry : fs::directory_iterator(tmp / target)) {
      EXPECT_NO_THROW(ParseInput(target, testing::ReadText(entry.path())))
          << target << ": " << entry.path().filename();
      ++seeds;
    }
    EXPECT_GE(seeds, 1u) << target;
  }
}

TEST(FuzzInputs, EveryKeptFindingIsParsedOrRefusedWithAnInputError) {
  const fs::path kept = fs::path(TEXLUME_SOURCE_DIR) / "fuzz/regressions";
  ASSERT_TRUE(fs::is_directory(kept));
  for (const auto& folder : fs::directory_iterator(kept)) {
    if (!folder.is_directory()) continue;
    const std::string target = folder.path().filename().string();
    ASSERT_NE(std::find(Targets().begin(), Targets().end(), target), Targets().end()) << target;
    for (const auto& input : fs::directory_iterator(folder.path())) {
      try {
        ParseInput(target, testing::ReadText(input.path()));
      } catch (const InputError&) {
      } catch (const std::exception& e) {
        ADD_FAILURE() << input.path() << " throws " << e.what();
      }
    }
  }
}

TEST(FuzzInputs, MalformedBytesAreRefusedWithAnInputError) {
  for (const std::string& target : Targets()) {
    EXPECT_THROW(ParseInput(target, std::string("\xff\x00garbage", 9)), InputError) << target;
  }
  EXPECT_THROW(ParseInput("no_such_target", ""), std::invalid_argument);
}

}  // namespace
}  // namespace texlume::fuzz
