// Cross-checks against the real COLMAP program: models written by texlume are
// converted and analysed by `colmap`, and COLMAP's output is read back.
#include <gtest/gtest.h>

#include <regex>

#include "sfm/colmap_io.h"
#include "sfm/inspect.h"
#include "tests/sfm/reconstruction_matchers.h"
#include "tests/test_util.h"

namespace texlume::sfm {
namespace {

using testing::RunCommand;
using testing::TempDir;

void RequireColmap() {
  if (!TEXLUME_COLMAP_TESTS) GTEST_SKIP() << "TEXLUME_COLMAP_TESTS is OFF";
  std::string out;
  ASSERT_EQ(RunCommand("command -v colmap", &out), 0)
      << "the colmap program is missing: run scripts/install_deps.sh";
}

std::string Colmap(const std::string& args) {
  std::string out;
  const int code = RunCommand("QT_QPA_PLATFORM=offscreen colmap " + args, &out);
  EXPECT_EQ(code, 0) << "colmap " << args << "\n" << out;
  return out;
}

TEST(ColmapCrossCheck, TextWrittenByTexlumeConvertedByColmapToBinaryReadsBackEqual) {
  RequireColmap();
  TempDir tmp;
  const Reconstruction r = MakeTestReconstruction(5);
  WriteModel(r, tmp / "ours_txt", ModelFormat::kText);
  std::filesystem::create_directories(tmp / "colmap_bin");
  Colmap("model_converter --input_path " + (tmp / "ours_txt").string() + " --output_path " +
         (tmp / "colmap_bin").string() + " --output_type BIN");
  const LoadedModel back = ReadModel(tmp / "colmap_bin");
  EXPECT_EQ(back.format, ModelFormat::kBinary);
  ExpectSameReconstruction(r, back.reconstruction, 1e-12);
}

TEST(ColmapCrossCheck, BinaryWrittenByTexlumeConvertedByColmapToTextReadsBackEqual) {
  RequireColmap();
  TempDir tmp;
  const Reconstruction r = MakeTestReconstruction(6);
  WriteModel(r, tmp / "ours_bin", ModelFormat::kBinary);
  std::filesystem::create_directories(tmp / "colmap_txt");
  Colmap("model_converter --input_path " + (tmp / "ours_bin").string() + " --output_path " +
         (tmp / "colmap_txt").string() + " --output_type TXT");
  const LoadedModel back = ReadModel(tmp / "colmap_txt");
  EXPECT_EQ(back.format, ModelFormat::kText);
  ExpectSameReconstruction(r, back.reconstruction, 1e-12);
}

TEST(ColmapCrossCheck, ModelAnalyzerReportsTheCountsTexlumeInspectReports) {
  RequireColmap();
  TempDir tmp;
  const Reconstruction r = MakeTestReconstruction(7);
  WriteModel(r, tmp / "model", ModelFormat::kBinary);
  const std::string analyzer = Colmap("model_analyzer --path " + (tmp / "model").string());
  InspectOptions options;
  options.model_dir = tmp / "model";
  const std::string ours = FormatInspectReport(RunInspect(options));
  // Every statistic line COLMAP prints appears verbatim in texlume's summary.
  const std::regex stat(
      R"((Cameras|Images|Registered images|Points|Observations|Mean track length|Mean observations per image|Mean reprojection error): ([0-9.]+)(px)?)");
  int compared = 0;
  for (std::sregex_iterator it(analyzer.begin(), analyzer.end(), stat), end; it != end; ++it) {
    const std::string name = (*it)[1];
    const std::string value = (*it)[2];
    const std::regex ours_stat(name + R"(: ([0-9.]+))");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(ours, m, ours_stat)) << name << " missing in\n" << ours;
    EXPECT_NEAR(std::stod(m[1]), std::stod(value), 1e-6 * std::max(1.0, std::stod(value))) << name;
    ++compared;
  }
  EXPECT_EQ(compared, 8) << analyzer;
}

}  // namespace
}  // namespace texlume::sfm
