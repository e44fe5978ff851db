// End-to-end tests of the texlume program: exit codes and messages for good and
// bad input, as a user sees them.
#include <gtest/gtest.h>

#include <fstream>

#include "datasets_synthetic/object_scene.h"
#include "tests/test_util.h"

namespace texlume {
namespace {

using testing::RunCommand;
using testing::TempDir;
using testing::WriteText;

int Texlume(const std::string& args, std::string* out) {
  return RunCommand(std::string(TEXLUME_BINARY) + " " + args, out);
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    datasets::ObjectSceneOptions options;
    options.num_images = 6;
    datasets::WriteObjectScene(datasets::MakeObjectScene(options), tmp_.path());
  }
  std::string Path(const std::string& name) const { return (tmp_ / name).string(); }
  void Corrupt(const std::string& name, std::size_t keep_bytes) const {
    const std::string bytes = testing::ReadText(tmp_ / name);
    WriteText(tmp_ / name, bytes.substr(0, keep_bytes));
  }
  TempDir tmp_;
};

TEST_F(CliTest, InspectSucceedsOnAGoodScene) {
  std::string out;
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse") + " --mesh " + Path("mesh.ply") +
                        " --lights " + Path("lights.json") + " --json " + Path("report.json"),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("Images: 6"), std::string::npos) << out;
  EXPECT_NE(out.find("Triangles fully seen by >= 1 photo"), std::string::npos) << out;
  EXPECT_TRUE(std::filesystem::exists(tmp_ / "report.json"));
}

TEST_F(CliTest, UsageErrorsExitWithTwo) {
  std::string out;
  EXPECT_EQ(Texlume("", &out), 2);
  EXPECT_EQ(Texlume("frobnicate", &out), 2);
  EXPECT_NE(out.find("unknown command"), std::string::npos);
  EXPECT_EQ(Texlume("inspect", &out), 2);
  EXPECT_NE(out.find("--model is required"), std::string::npos) << out;
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse") + " --bogus 1", &out), 2);
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse") + " --max-buffer-size 3", &out), 2);
  EXPECT_EQ(Texlume("--help", &out), 0);
}

TEST_F(CliTest, TruncatedBinaryModelIsACleanErrorNamingTheFile) {
  Corrupt("sparse/points3D.bin", 100);
  std::string out;
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse"), &out), 1);
  EXPECT_NE(out.find("points3D.bin"), std::string::npos) << out;
  EXPECT_TRUE(out.find("truncated") != std::string::npos ||
              out.find("corrupt") != std::string::npos)
      << out;
}

TEST_F(CliTest, CorruptCountIsACleanError) {
  std::string bytes = testing::ReadText(tmp_ / "sparse/images.bin");
  bytes[0] = '\xff';
  bytes[5] = '\x7f';
  WriteText(tmp_ / "sparse/images.bin", bytes);
  std::string out;
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse"), &out), 1);
  EXPECT_NE(out.find("images.bin"), std::string::npos) << out;
}

TEST_F(CliTest, MalformedTextLineNamesFileAndLine) {
  std::ofstream(tmp_ / "sparse_txt/cameras.txt", std::ios::app) << "2 PINHOLE 640 480 1 2\n";
  std::string out;
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse_txt"), &out), 1);
  EXPECT_NE(out.find("cameras.txt:5:"), std::string::npos) << out;
}

TEST_F(CliTest, BadMeshLightsAndMissingImagesAreCleanErrors) {
  std::string out;
  WriteText(tmp_ / "broken.obj", "v 0 0 0\nf 1 2 3\n");
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse") + " --mesh " + Path("broken.obj"), &out),
            1);
  EXPECT_NE(out.find("broken.obj"), std::string::npos) << out;

  WriteText(tmp_ / "bad_lights.json", R"({"images": {"nope.png": {"direction": [0, 0, 1]}}})");
  EXPECT_EQ(
      Texlume("inspect --model " + Path("sparse") + " --lights " + Path("bad_lights.json"), &out),
      1);
  EXPECT_NE(out.find("nope.png"), std::string::npos) << out;

  std::filesystem::create_directories(tmp_ / "photos");
  EXPECT_EQ(Texlume("inspect --model " + Path("sparse") + " --images " + Path("photos"), &out), 1);
  EXPECT_NE(out.find("missing"), std::string::npos) << out;
  EXPECT_NE(out.find("image_000.png"), std::string::npos) << out;
}

TEST(Cli, DemoWritesTheSceneInspectsItAndRecordsTheRun) {
  TempDir tmp;
  std::string out;
  EXPECT_EQ(
      Texlume("demo --out " + (tmp / "demo").string() + " --kind plane --material brick", &out), 0)
      << out;
  EXPECT_NE(out.find("Images: 36"), std::string::npos) << out;
  EXPECT_NE(out.find("Images missing on disk: 0"), std::string::npos) << out;
  for (const std::string f :
       {"scene/object/sparse/cameras.bin", "scene/object/sparse_txt/images.txt",
        "scene/object/mesh.ply", "scene/object/lights.json", "scene/material/capture/lights.lp",
        "scene/MANIFEST.md", "run.json"}) {
    EXPECT_TRUE(std::filesystem::exists(tmp / "demo" / f)) << f;
  }
}

TEST(Cli, SceneRefusesUnknownKindsAndMaterials) {
  TempDir tmp;
  std::string out;
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --kind cube", &out), 2);
  EXPECT_NE(out.find("--kind"), std::string::npos) << out;
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --material marble", &out), 2);
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --images 1", &out), 2);
  EXPECT_NE(out.find("num_images"), std::string::npos) << out;
}

}  // namespace
}  // namespace texlume
