// End-to-end tests of the texlume program: exit codes and messages for good and
// bad input, as a user sees them.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "datasets_synthetic/object_scene.h"
#include "datasets_synthetic/scene.h"
#include "ptm/horizon.h"
#include "tests/test_util.h"

namespace texlume {
namespace {

using testing::RunCommand;
using testing::TempDir;
using testing::WriteText;

int Texlume(const std::string& args, std::string* out) {
  std::string command = TEXLUME_BINARY;  // appended, not `std::string(...) + " "`: GCC 12
  command += ' ';                        // sees that through the precompiled header as
  command += args;                       // out of bounds (-Warray-bounds)
  return RunCommand(command, out);
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

// Every subcommand has its own help, listing each option with its default;
// typos get the nearest name.
TEST(Cli, HelpListsEveryOptionAndTyposGetTheNearestName) {
  std::string out;
  for (const char* sub : {"inspect", "fit", "btf", "relight", "lights-from-sphere", "synth2d",
                          "synth", "render", "view", "scene", "demo"}) {
    EXPECT_EQ(Texlume(std::string(sub) + " --help", &out), 0) << sub << "\n" << out;
    EXPECT_NE(out.find("Usage: texlume " + std::string(sub)), std::string::npos) << out;
  }
  ASSERT_EQ(Texlume("synth --help", &out), 0);
  for (const char* option : {"--btf", "--chart-flattening", "--correction-prior-shrink",
                             "--seam-band", "--no-detail-transfer", "--tangent-field"})
    EXPECT_NE(out.find(option), std::string::npos) << option << "\n" << out;
  EXPECT_NE(out.find("--chart-stretch FLOAT=1.25"), std::string::npos) << out;
  EXPECT_EQ(Texlume("help", &out), 0);
  EXPECT_NE(out.find("lights-from-sphere"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --modle x --images b", &out), 2);
  EXPECT_NE(out.find("did you mean --model?"), std::string::npos) << out;
  EXPECT_EQ(Texlume("inspct --model x", &out), 2);
  EXPECT_NE(out.find("did you mean 'inspect'?"), std::string::npos) << out;
  EXPECT_EQ(Texlume("render --model m --cameras c --lights l --out r --samples=9", &out), 2);
  EXPECT_NE(out.find("samples must be in [1, 8]"), std::string::npos) << out;
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

TEST(Cli, DemoRunsTheWholeJobAndWritesTheReport) {
  TempDir tmp;
  std::string out;
  EXPECT_EQ(Texlume("demo --out " + (tmp / "demo").string() +
                        " --kind plane --material brick --images 12 --width 320 --height 240",
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("Images: 12"), std::string::npos) << out;
  EXPECT_NE(out.find("Images missing on disk: 0"), std::string::npos) << out;
  EXPECT_NE(out.find("texlume synth"), std::string::npos) << out;
  for (const std::string f :
       {"scene/object/sparse/cameras.bin", "scene/object/sparse_txt/images.txt",
        "scene/object/mesh.ply", "scene/object/lights.json", "scene/material/capture/lights.lp",
        "scene/MANIFEST.md", "run.json", "sample.ptm", "model/model.glb", "model/manifest.json",
        "render_texlume/render.json", "render_flat/render.json", "render_baked/render.json",
        "report.html"}) {
    EXPECT_TRUE(std::filesystem::exists(tmp / "demo" / f)) << f;
  }
  const std::string report = testing::ReadText(tmp / "demo/report.html");
  EXPECT_NE(report.find("flat baseline"), std::string::npos);
  EXPECT_NE(report.find("Held-out views under held-out lights"), std::string::npos);
  EXPECT_NE(report.find("report/view_0_texlume_error.png"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(tmp / "demo/report/view_0_texlume_error.png"));
  EXPECT_TRUE(std::filesystem::exists(tmp / "demo/model/report.html"));
}

TEST(Cli, SynthAndRenderRefuseBadCommandLinesAndInputs) {
  TempDir tmp;
  std::string out;
  // No texel size: a usage error (2); a missing model: an input error naming it (1).
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e --out f", &out), 2);
  EXPECT_NE(out.find("sample-texel-size"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model " + (tmp / "none").string() +
                        " --images b --lights c --mesh d "
                        "--sample e --sample-texel-size 0.01 --out " +
                        (tmp / "f").string(),
                    &out),
            1);
  EXPECT_NE(out.find("none"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "f"));
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --atlas boxes",
                    &out),
            2);
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --chart-flattening curved",
                    &out),
            2);
  EXPECT_NE(out.find("chart-flattening"), std::string::npos) << out;
  // A stretch bound out of range is refused before anything is read.
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --chart-flattening conformal "
                    "--chart-stretch 0.5",
                    &out),
            2);
  EXPECT_NE(out.find("stretch"), std::string::npos) << out;
  // So is a prior shrink that is neither auto nor in [0, 1].
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --correction-prior-shrink 1.5",
                    &out),
            2);
  EXPECT_NE(out.find("correction-prior-shrink"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --correction-prior-shrink often",
                    &out),
            2);
  // So is a tangent frame that is not one of the three, or given with a field.
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --tangent-frame sideways",
                    &out),
            2);
  EXPECT_NE(out.find("--tangent-frame: give first-edge, photos or auto"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --tangent-frame photos --tangent-field 0,0,1",
                    &out),
            2);
  // A placement search that is not one of the two, or no candidates.
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --search sideways",
                    &out),
            2);
  EXPECT_NE(out.find("--search"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --search-candidates 0",
                    &out),
            2);
  EXPECT_NE(out.find("search candidates must be >= 1"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --photometry-faces 10",
                    &out),
            2);
  EXPECT_NE(out.find("photometry_faces must be >= 64"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --compare-regions 2,1",
                    &out),
            2);
  EXPECT_NE(out.find("--compare-regions takes 2 to 4096 regions, not 1"), std::string::npos) << out;
  // Region comparison measures blended seams: not a BTF's graph cuts, nor the graph-cut engine's.
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --btf " + tmp.path().string() +
                        " --out f --compare-regions 2",
                    &out),
            2);
  EXPECT_NE(out.find("--compare-regions measures a PTM or colour sample's edges"),
            std::string::npos)
      << out;
  EXPECT_EQ(Texlume("synth --engine graphcut --mesh d --sample e --sample-texel-size 0.01 --out f "
                    "--compare-regions 2",
                    &out),
            2);
  EXPECT_NE(out.find("--compare-regions is not taken by --engine graphcut"), std::string::npos)
      << out;
  // A sample horizon that is not the EXR of texlume fit --horizon, or without a PTM
  // sample, or with the graph-cut engine.
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --sample-horizon h.png",
                    &out),
            2);
  EXPECT_NE(out.find("--sample-horizon is the .exr"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --btf " + tmp.path().string() +
                        " --out f --sample-horizon h.exr",
                    &out),
            2);
  EXPECT_EQ(Texlume("synth --engine graphcut --mesh d --sample e --sample-texel-size 0.01 --out f "
                    "--sample-horizon h.exr",
                    &out),
            2);
  EXPECT_NE(out.find("--sample-horizon is not taken by --engine graphcut"), std::string::npos)
      << out;
  // Shadows in the synthesis need the horizon map.
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --shadowed-synthesis",
                    &out),
            2);
  EXPECT_NE(out.find("--shadowed-synthesis requires --sample-horizon"), std::string::npos) << out;
  // A photo cache that is not a size (photos on demand, docs/cli.md).
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --photo-cache lots",
                    &out),
            2);
  EXPECT_EQ(Texlume("render --model " + (tmp / "nomodel").string() +
                        " --cameras c --lights l "
                        "--out " +
                        (tmp / "r").string(),
                    &out),
            1);
  EXPECT_NE(out.find("manifest.json"), std::string::npos) << out;
  EXPECT_EQ(Texlume("render --model m --cameras c --lights l --out r --baseline shiny", &out), 2);
}

TEST(Cli, ViewRefusesBadCommandLinesAndFoldersThatAreNotModels) {
  TempDir tmp;
  std::string out;
  EXPECT_EQ(Texlume("view", &out), 2);
  EXPECT_EQ(Texlume("view a b", &out), 2);
  EXPECT_EQ(Texlume("view " + tmp.path().string() + " --port 70000", &out), 2);
  EXPECT_EQ(Texlume("view " + (tmp / "nomodel").string() + " --port 0", &out), 1);
  EXPECT_NE(out.find("manifest.json"), std::string::npos) << out;
}

TEST(Cli, ViewRefusesAMissingOrStaleViewerBundle) {
  TempDir tmp;
  const std::filesystem::path web = tmp / "web";
  std::filesystem::create_directories(web / "viewer");
  std::filesystem::create_directories(web / "dist");
  WriteText(web / "viewer/index.html", "<!doctype html>");
  WriteText(web / "viewer/viewer.js", "// source");
  const std::string view = "env TEXLUME_WEB_DIR=" + web.string() + " " +
                           std::string(TEXLUME_BINARY) + " view " + (tmp / "nomodel").string() +
                           " --port 0";
  std::string out;
  EXPECT_EQ(testing::RunCommand(view, &out), 1);
  EXPECT_NE(out.find("dist/viewer.js"), std::string::npos) << out;
  // A bundle older than the viewer's source is not served.
  WriteText(web / "dist/viewer.js", "// bundle");
  std::filesystem::last_write_time(
      web / "dist/viewer.js",
      std::filesystem::last_write_time(web / "viewer/viewer.js") - std::chrono::hours(1));
  EXPECT_EQ(testing::RunCommand(view, &out), 1);
  EXPECT_NE(out.find("is older than viewer/viewer.js"), std::string::npos) << out;
  // A fresh one is: the model folder is what is wrong now.
  std::filesystem::last_write_time(
      web / "dist/viewer.js",
      std::filesystem::last_write_time(web / "viewer/viewer.js") + std::chrono::hours(1));
  EXPECT_EQ(testing::RunCommand(view, &out), 1);
  EXPECT_NE(out.find("manifest.json"), std::string::npos) << out;
}

TEST(Cli, SceneRefusesUnknownKindsAndMaterials) {
  TempDir tmp;
  std::string out;
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --kind cube", &out), 2);
  EXPECT_NE(out.find("--kind"), std::string::npos) << out;
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --material marble", &out), 2);
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --images 1", &out), 2);
  EXPECT_NE(out.find("num_images"), std::string::npos) << out;
  // Monument-scale options: out of range, or more rings than photos.
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --mesh-faces -5", &out), 2);
  EXPECT_NE(out.find("mesh_faces"), std::string::npos) << out;
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --images 4 --camera-rings 5", &out),
            2);
  EXPECT_NE(out.find("camera_rings"), std::string::npos) << out;
  EXPECT_EQ(Texlume("scene --out " + tmp.path().string() + " --camera-distance 1", &out), 2);
  EXPECT_FALSE(std::filesystem::exists(tmp / "scene.json"));
}

class FitCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    datasets::SceneOptions o =
        datasets::MaterialOnlySceneOptions(datasets::MaterialKind::kStone, 24, 12);
    o.num_held_out_capture_lights = 2;
    o.material.texel_size = 0.01;
    datasets::GenerateScene(o, tmp_.path());
    capture_ = (tmp_ / "material/capture").string();
  }
  TempDir tmp_;
  std::string capture_;
};

TEST_F(FitCliTest, FitWritesPtmExrWebAndRecordThenRelights) {
  std::string out;
  const std::string ptm = (tmp_ / "sample.ptm").string();
  ASSERT_EQ(Texlume("fit --images " + capture_ + " --lights " + capture_ + "/lights.lp --out " +
                        ptm + " --format rgb --exr " + (tmp_ / "sample.exr").string() + " --web " +
                        (tmp_ / "web").string(),
                    &out),
            0)
      << out;
  EXPECT_TRUE(std::filesystem::exists(ptm + ".json"));
  EXPECT_TRUE(std::filesystem::exists(tmp_ / "web/info.json"));
  EXPECT_EQ(Texlume("relight --ptm " + ptm + " --light 0.3,0.2,0.9 --out " +
                        (tmp_ / "relit.png").string() + " --normals " +
                        (tmp_ / "normals.png").string() + " --gain 2 --specular 0.5",
                    &out),
            0)
      << out;
  EXPECT_EQ(Texlume("relight --ptm " + (tmp_ / "sample.exr").string() + " --light 0,0,1 --out " +
                        (tmp_ / "relit2.png").string(),
                    &out),
            0)
      << out;
  EXPECT_TRUE(std::filesystem::exists(tmp_ / "normals.png"));
}

// fit --horizon writes the horizon map beside the PTM of the lit samples; relight
// --horizon casts the relief's shadows, which only ever take light away.
TEST_F(FitCliTest, FitWithHorizonWritesItAndRelightCastsItsShadows) {
  std::string out;
  const std::string ptm = (tmp_ / "lit.ptm").string(), horizon = (tmp_ / "horizon.exr").string();
  const std::string fit =
      "fit --images " + capture_ + " --lights " + capture_ + "/lights.lp --out ";
  ASSERT_EQ(Texlume(fit + ptm + " --format rgb --horizon " + horizon, &out), 0) << out;
  std::ifstream record_file(ptm + ".json");
  const nlohmann::json record = nlohmann::json::parse(record_file);
  EXPECT_EQ(record["settings"]["horizon"], horizon);
  EXPECT_EQ(record["result"]["horizon"]["sectors"], 16);
  EXPECT_GE(record["result"]["horizon"]["shadow_floor"].get<double>(), 0.0);
  EXPECT_LE(record["result"]["horizon"]["shadow_floor"].get<double>(), 1.0);

  const std::string relight = "relight --ptm " + ptm + " --light 0.9,0,0.42 --out ";
  ASSERT_EQ(Texlume(relight + (tmp_ / "shadowed.png").string() + " --horizon " + horizon, &out), 0)
      << out;
  ASSERT_EQ(Texlume(relight + (tmp_ / "unshadowed.png").string(), &out), 0) << out;
  const cv::Mat shadowed = cv::imread((tmp_ / "shadowed.png").string());
  const cv::Mat unshadowed = cv::imread((tmp_ / "unshadowed.png").string());
  ASSERT_EQ(shadowed.size(), unshadowed.size());
  cv::Mat brighter;
  cv::compare(shadowed, unshadowed + cv::Scalar::all(1), brighter, cv::CMP_GT);
  EXPECT_EQ(cv::countNonZero(brighter.reshape(1)), 0);

  // Refused: with --robust or an HSH fit, a horizon that is not .exr, a PTM EXR given
  // as the horizon, --gain with a horizon. Nothing is written.
  const std::string other = (tmp_ / "other.exr").string();
  EXPECT_EQ(Texlume(fit + (tmp_ / "r.ptm").string() + " --robust --horizon " + other, &out), 2);
  EXPECT_NE(out.find("--robust"), std::string::npos) << out;
  EXPECT_EQ(Texlume(fit + (tmp_ / "h.rti").string() + " --basis hsh --horizon " + other, &out), 2);
  EXPECT_EQ(
      Texlume(fit + (tmp_ / "p.ptm").string() + " --horizon " + (tmp_ / "h.png").string(), &out),
      2);
  EXPECT_FALSE(std::filesystem::exists(other));
  ASSERT_EQ(Texlume(fit + (tmp_ / "s.ptm").string() + " --exr " + other, &out), 0) << out;
  EXPECT_EQ(Texlume(relight + (tmp_ / "x.png").string() + " --horizon " + other, &out), 1);
  EXPECT_NE(out.find("horizon"), std::string::npos) << out;
  EXPECT_EQ(
      Texlume(relight + (tmp_ / "x.png").string() + " --horizon " + horizon + " --gain 2", &out),
      2);
  EXPECT_FALSE(std::filesystem::exists(tmp_ / "x.png"));
}

TEST_F(FitCliTest, BadCapturesAreCleanErrorsWithNothingWritten) {
  std::string out;
  const std::string ptm = (tmp_ / "bad.ptm").string();
  const std::string lp = capture_ + "/lights.lp";
  auto fit = [&](const std::string& lights) {
    return Texlume("fit --images " + capture_ + " --lights " + lights + " --out " + ptm, &out);
  };
  // A file named in the .lp but missing.
  std::filesystem::remove(tmp_ / "material/capture/rti_003.png");
  EXPECT_EQ(fit(lp), 1);
  EXPECT_NE(out.find("rti_003.png"), std::string::npos) << out;
  // Fewer than 6 lights.
  WriteText(tmp_ / "few.lp",
            "3\nrti_000.png 0 0 1\nrti_001.png 0.5 0 0.8\nrti_002.png 0 0.5 0.8\n");
  EXPECT_EQ(fit((tmp_ / "few.lp").string()), 1);
  EXPECT_NE(out.find("at least 6"), std::string::npos) << out;
  // A light below the horizon.
  std::string text = "6\n";
  for (int i = 4; i < 10; ++i) {
    text += "rti_00" + std::to_string(i) + ".png " + (i == 6 ? "0.6 0 -0.8" : "0.1 0.2 0.9") + "\n";
  }
  WriteText(tmp_ / "low.lp", text);
  EXPECT_EQ(fit((tmp_ / "low.lp").string()), 1);
  EXPECT_NE(out.find("horizon"), std::string::npos) << out;
  // Degenerate: every light the same.
  text = "6\n";
  for (int i = 4; i < 10; ++i) text += "rti_00" + std::to_string(i) + ".png 0.1 0.2 0.9\n";
  WriteText(tmp_ / "same.lp", text);
  EXPECT_EQ(fit((tmp_ / "same.lp").string()), 1);
  EXPECT_NE(out.find("degenerate"), std::string::npos) << out;
  // Images of different sizes.
  std::filesystem::copy_file(tmp_ / "object/images/image_000.png",
                             tmp_ / "material/capture/rti_005.png",
                             std::filesystem::copy_options::overwrite_existing);
  text = "6\n";
  for (int i = 4; i < 10; ++i) {
    const double a = i * 1.1, r = i % 2 ? 0.3 : 0.7;
    text += "rti_00" + std::to_string(i) + ".png " + std::to_string(r * std::cos(a)) + " " +
            std::to_string(r * std::sin(a)) + " " + std::to_string(std::sqrt(1 - r * r)) + "\n";
  }
  WriteText(tmp_ / "sizes.lp", text);
  EXPECT_EQ(fit((tmp_ / "sizes.lp").string()), 1);
  EXPECT_NE(out.find("rti_005.png"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(ptm));
  // Corrupt and truncated .ptm files for relight.
  WriteText(tmp_ / "corrupt.ptm", "PTM_1.2\nPTM_FORMAT_RGB\n10\n10\n1 1 1 1 1 1\n0 0 0 0 0 0\nabc");
  EXPECT_EQ(Texlume("relight --ptm " + (tmp_ / "corrupt.ptm").string() + " --light 0,0,1 --out " +
                        (tmp_ / "x.png").string(),
                    &out),
            1);
  EXPECT_NE(out.find("truncated payload"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp_ / "x.png"));
  EXPECT_EQ(Texlume("relight --ptm " + (tmp_ / "corrupt.ptm").string() + " --light 0,0,-1 --out " +
                        (tmp_ / "x.png").string(),
                    &out),
            2);
}

TEST_F(FitCliTest, Synth2dBuildsAPtmFromPhotosAndRefusesBadPhotos) {
  std::string out;
  const std::string sample = (tmp_ / "sample.ptm").string();
  ASSERT_EQ(
      Texlume("fit --images " + capture_ + " --lights " + capture_ + "/lights.lp --out " + sample,
              &out),
      0)
      << out;
  const std::string photos = (tmp_ / "material/surface/photos").string();
  const std::string base = "synth2d --sample " + sample + " --photos " + photos + " --lights " +
                           photos + "/lights.lp --scale 2 --block 8 --overlap 2 --out ";
  ASSERT_EQ(Texlume(base + (tmp_ / "out").string(), &out), 0) << out;
  for (const std::string f : {"ptm_out.ptm", "ptm_out.exr", "relit_photo_00.png",
                              "comparison_photo_01.png", "relit_new_0.png", "synth2d.json"}) {
    EXPECT_TRUE(std::filesystem::exists(tmp_ / "out" / f)) << f;
  }
  // Blocks that do not fit the photo scale, or the sample.
  EXPECT_EQ(Texlume(base + (tmp_ / "bad").string() + " --block 7", &out), 2);
  EXPECT_EQ(Texlume(base + (tmp_ / "bad").string() + " --block 64", &out), 2);
  EXPECT_NE(out.find("does not fit"), std::string::npos) << out;
  // Output size that the photos do not cover at a whole scale.
  EXPECT_EQ(Texlume(base + (tmp_ / "bad").string() + " --width 25 --height 25", &out), 1);
  // A photo named in the .lp but missing.
  std::filesystem::remove(tmp_ / "material/surface/photos/photo_01.png");
  EXPECT_EQ(Texlume(base + (tmp_ / "bad").string(), &out), 1);
  EXPECT_NE(out.find("photo_01.png"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp_ / "bad"));
}

// A small synthetic scene with a BTF capture of the material (6 views x 12
// lights) and an object seen in `num_images` photos of `size` pixels.
datasets::SceneOptions SmallBtfScene(int num_images, int size, int btf_size) {
  datasets::SceneOptions options;
  options.num_images = num_images;
  options.image_width = size;
  options.image_height = size;
  options.num_held_out_views = 0;
  options.capture_size = 16;
  options.num_capture_lights = 6;
  options.num_held_out_capture_lights = 0;
  options.write_surface = false;
  options.btf_size = btf_size;
  return options;
}

// `texlume btf` on the synthetic scene's BTF capture: writes the factorisation
// and the error table, falling with n; refuses bad command lines and captures.
TEST(Cli, BtfFactorisesTheSceneCaptureAndRefusesBadInput) {
  TempDir tmp;
  datasets::GenerateScene(SmallBtfScene(3, 64, 32), tmp.path() / "scene");
  const std::string capture = (tmp / "scene").string() + "/material/btf";
  std::string out;
  ASSERT_EQ(
      Texlume("btf --capture " + capture + " --out " + (tmp / "svd").string() + " --components 8",
              &out),
      0)
      << out;
  const nlohmann::json j = nlohmann::json::parse(testing::ReadText(tmp / "svd/btf_svd.json"));
  EXPECT_EQ(j["components"].get<int>(), 8);
  EXPECT_TRUE(std::filesystem::exists(tmp / "svd/geometry_maps.exr"));
  EXPECT_TRUE(std::filesystem::exists(tmp / "svd/run.json"));
  double previous = 1e9;
  for (const auto& row : j["errors"]) {
    EXPECT_LE(row["rms"].get<double>(), previous);
    previous = row["rms"].get<double>();
  }
  EXPECT_NE(out.find("8 (kept)"), std::string::npos) << out;
  // 6 views x 12 lights x 3 channels = 216 columns at most.
  EXPECT_EQ(
      Texlume("btf --capture " + capture + " --out " + (tmp / "x").string() + " --components 217",
              &out),
      2);
  EXPECT_NE(out.find("[1, 216]"), std::string::npos) << out;
  EXPECT_EQ(Texlume("btf --out " + (tmp / "x").string(), &out), 2);
  EXPECT_EQ(
      Texlume("btf --capture " + (tmp / "nothing").string() + " --out " + (tmp / "x").string(),
              &out),
      1);
  EXPECT_NE(out.find("btf.json"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "x"));
}

TEST(Cli, SynthWithABtfSampleRendersAsABtfAndRefusesBadInput) {
  TempDir tmp;
  datasets::SceneOptions options = SmallBtfScene(8, 96, 40);
  options.focal_px = 90;
  options.num_held_out_views = 1;
  options.held_out_lights_per_view = 1;
  options.material.texel_size = 0.01;
  datasets::GenerateScene(options, tmp.path() / "scene");
  const std::string scene = (tmp / "scene").string();
  const std::string inputs = " --model " + scene + "/object/sparse --images " + scene +
                             "/object/images --lights " + scene + "/object/lights.json --mesh " +
                             scene + "/object/mesh.ply --atlas-size 512 --no-report";
  const std::string model = (tmp / "model").string();
  std::string out;
  ASSERT_EQ(
      Texlume("synth" + inputs + " --btf " + scene +
                  "/material/btf --components 8 --search exhaustive --search-candidates 20 --out " +
                  model,
              &out),
      0)
      << out;
  EXPECT_NE(out.find("graph-cut seams"), std::string::npos) << out;
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp / "model/manifest.json"));
  EXPECT_EQ(manifest["btf"]["format"], "texlume-btf-model-1");
  EXPECT_EQ(manifest["settings"]["components"].get<int>(), 8);
  // The placement search's settings reach the BTF job.
  EXPECT_EQ(manifest["settings"]["search"], "exhaustive");
  EXPECT_EQ(manifest["settings"]["search_candidates"].get<int>(), 20);
  const std::string held = scene + "/object/held_out";
  const std::string render = "render --model " + model + " --cameras " + held +
                             "/sparse --lights " + held + "/lights.json --truth " + held +
                             "/images --truth-masks " + held + "/masks --out ";
  ASSERT_EQ(Texlume(render + (tmp / "r").string(), &out), 0) << out;
  EXPECT_EQ(nlohmann::json::parse(testing::ReadText(tmp / "r/render.json"))["settings"]["mode"],
            "btf");
  ASSERT_EQ(Texlume(render + (tmp / "f").string() + " --baseline flat", &out), 0) << out;
  EXPECT_EQ(nlohmann::json::parse(testing::ReadText(tmp / "f/render.json"))["settings"]["mode"],
            "flat");
  // Bad input: both samples, a missing capture, more components than the data.
  EXPECT_EQ(Texlume("synth" + inputs + " --btf " + scene + "/material/btf --sample x.ptm --out " +
                        (tmp / "x").string(),
                    &out),
            2);
  EXPECT_EQ(Texlume("synth" + inputs + " --btf " + (tmp / "nothing").string() + " --out " +
                        (tmp / "x").string(),
                    &out),
            1);
  EXPECT_NE(out.find("btf.json"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth" + inputs + " --btf " + scene + "/material/btf --components 999 --out " +
                        (tmp / "x").string(),
                    &out),
            2);
  EXPECT_NE(out.find("[1, 216]"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "x"));
}

// A small scene for colour samples (material texel 0.01), with a BTF capture of
// btf_size texels a side when that is not 0: its folder.
std::string WriteColourSampleScene(const TempDir& tmp, int btf_size = 0) {
  datasets::SceneOptions options = SmallBtfScene(8, 96, std::max(btf_size, 16));
  options.write_btf = btf_size > 0;
  options.capture_size = 64;
  options.focal_px = 90;
  options.num_held_out_views = 1;
  options.held_out_lights_per_view = 1;
  options.material.texel_size = 0.01;
  datasets::GenerateScene(options, tmp.path() / "scene");
  return (tmp / "scene").string();
}

// Renders tmp/model at the scene's held-out views against their truth into
// tmp/r: the exit code, and render.json when it is 0.
int RenderHeldOut(const TempDir& tmp, const std::string& scene, std::string* out,
                  nlohmann::json* render) {
  const std::string held = scene + "/object/held_out";
  const int code =
      Texlume("render --model " + (tmp / "model").string() + " --cameras " + held +
                  "/sparse --lights " + held + "/lights.json --truth " + held +
                  "/images --truth-masks " + held + "/masks --out " + (tmp / "r").string(),
              out);
  if (code == 0) *render = nlohmann::json::parse(testing::ReadText(tmp / "r/render.json"));
  return code;
}

// The main job with a colour sample (an ordinary photo of the material): a
// model folder of PTM atlases that `texlume render` draws; a sample that is no
// image is an input error naming it.
TEST(Cli, SynthWithAColourSampleWritesAModelThatRenders) {
  TempDir tmp;
  const std::string scene = WriteColourSampleScene(tmp);
  const std::string inputs = " --model " + scene + "/object/sparse --images " + scene +
                             "/object/images --lights " + scene + "/object/lights.json --mesh " +
                             scene + "/object/mesh.ply --atlas-size 512 --no-report" +
                             " --sample-texel-size 0.01";
  std::string out;
  ASSERT_EQ(Texlume("synth" + inputs + " --sample " + scene +
                        "/material/capture/rti_005.png --out " + (tmp / "model").string(),
                    &out),
            0)
      << out;
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp / "model/manifest.json"));
  EXPECT_EQ(manifest["settings"]["sample_kind"], "colour");
  nlohmann::json render;
  ASSERT_EQ(RenderHeldOut(tmp, scene, &out, &render), 0) << out;
  EXPECT_GT(render["metrics"]["mean_psnr_db"].get<double>(), 10.0);
  testing::WriteText(tmp / "not_an_image.png", "plain text");
  EXPECT_EQ(Texlume("synth" + inputs + " --sample " + (tmp / "not_an_image.png").string() +
                        " --out " + (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("not_an_image.png"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
  // A horizon map goes with a PTM sample: refused with a colour photo, naming the file.
  const std::string capture = scene + "/material/capture";
  ptm::SelfShadowing shadowing;
  shadowing.horizon.width = shadowing.horizon.height = 64;
  shadowing.horizon.sectors = 8;
  shadowing.horizon.elevation_rad.assign(64 * 64 * 8, 0.1f);
  ptm::WriteSelfShadowingExr(shadowing, tmp / "h.exr");
  EXPECT_EQ(Texlume("synth" + inputs + " --sample " + capture + "/rti_005.png --sample-horizon " +
                        (tmp / "h.exr").string() + " --out " + (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("h.exr: a horizon map goes with a PTM sample"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
}

// Graph-cut quilting (issue 32, docs/quilting.md): a mesh and a sample, no photos.
TEST(Cli, SynthGraphcutQuiltsAMeshWithoutPhotosAndRefusesBadInput) {
  TempDir tmp;
  const std::string scene = WriteColourSampleScene(tmp);
  const std::string inputs =
      " --engine graphcut --mesh " + scene +
      "/object/mesh.ply --atlas-size 512 --sample-texel-size 0.01 --sample " + scene +
      "/material/capture/rti_005.png --work-patch 16";
  std::string out;
  ASSERT_EQ(Texlume("synth" + inputs + " --out " + (tmp / "model").string(), &out), 0) << out;
  EXPECT_NE(out.find("graph-cut patches"), std::string::npos) << out;
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp / "model/manifest.json"));
  EXPECT_EQ(manifest["settings"]["engine"], "graphcut");
  EXPECT_EQ(manifest["settings"]["work_patch_levels"], 16);
  EXPECT_GT(manifest["summary"]["dense_samples"].get<int>(), 1000);
  EXPECT_GT(manifest["summary"]["patches"].get<int>(), 1);
  EXPECT_LT(manifest["summary"]["seam_cost_per_cut_link"].get<double>(),
            manifest["summary"]["unrelated_cut_cost"].get<double>());
  // Its report: the quilting's figures, the model from views around it; every
  // picture it shows exists.
  const std::string html = testing::ReadText(tmp / "model/report.html");
  for (const char* part : {"dense samples", "graph-cut quilting", "Light sweep", "Atlases"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  const std::vector<std::string> links = testing::ReportLinks(html);
  EXPECT_GE(links.size(), 5u + 4u * 2u + 1u + 1u);
  for (const std::string& link : links)
    EXPECT_TRUE(std::filesystem::exists(tmp / "model" / link)) << link;
  nlohmann::json render;
  ASSERT_EQ(RenderHeldOut(tmp, scene, &out, &render), 0) << out;
  EXPECT_GT(render["metrics"]["mean_psnr_db"].get<double>(), 10.0);
  // Photos to follow need --model, --images and --lights together, and the
  // photos' settings need photos (2); with all three, the photos are read (a
  // lights file that is not there: an input error naming it, 1).
  EXPECT_EQ(Texlume("synth" + inputs + " --model a --out " + (tmp / "bad").string(), &out), 2);
  EXPECT_NE(out.find("--model, --images and --lights"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth" + inputs + " --photo-cache 1G --out " + (tmp / "bad").string(), &out),
            2);
  EXPECT_NE(out.find("--photo-cache is for --engine triangle"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth" + inputs + " --top-k 3 --out " + (tmp / "bad").string(), &out), 2);
  EXPECT_NE(out.find("--top-k is for --engine graphcut with photos"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth" + inputs + " --model " + scene + "/object/sparse --images " + scene +
                        "/object/images --lights " + (tmp / "no_lights.json").string() + " --out " +
                        (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("no_lights.json"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth --engine graphcut --mesh m --sample s --out o", &out), 2);
  EXPECT_NE(out.find("sample-texel-size"), std::string::npos) << out;
  EXPECT_EQ(Texlume("synth" + inputs + " --engine quilting --out o", &out), 2);
  // A field file naming a face the mesh does not have: an input error naming it (1).
  testing::WriteText(
      tmp / "field.json",
      R"({"format": "texlume-field", "vectors": [{"face": 99999999, "direction": [1, 0, 0]}]})");
  EXPECT_EQ(Texlume("synth" + inputs + " --field " + (tmp / "field.json").string() + " --out " +
                        (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("field.json"), std::string::npos) << out;
  // Options of one engine are refused by the other (2).
  EXPECT_EQ(
      Texlume("synth" + inputs + " --no-detail-transfer --out " + (tmp / "bad").string(), &out), 2);
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --work-patch 8",
                    &out),
            2);
  EXPECT_NE(out.find("--work-patch is for --engine graphcut"), std::string::npos) << out;
  // --fill-unseen: one of two words, and not for the graph-cut engine (2).
  EXPECT_EQ(Texlume("synth --model a --images b --lights c --mesh d --sample e "
                    "--sample-texel-size 0.01 --out f --fill-unseen blur",
                    &out),
            2);
  EXPECT_NE(out.find("give overlap or graphcut"), std::string::npos) << out;
  EXPECT_EQ(
      Texlume("synth" + inputs + " --fill-unseen graphcut --out " + (tmp / "bad").string(), &out),
      2);
  EXPECT_NE(out.find("--fill-unseen is not taken by --engine graphcut"), std::string::npos) << out;
  EXPECT_EQ(
      Texlume("synth" + inputs + " --search exhaustive --out " + (tmp / "bad").string(), &out), 2);
  EXPECT_NE(out.find("--search is not taken by --engine graphcut"), std::string::npos) << out;
  // A sample smaller than the smallest work patch: an input error naming it (1).
  cv::imwrite((tmp / "tiny.png").string(), cv::Mat(12, 12, CV_8UC3, cv::Scalar(90, 120, 150)));
  EXPECT_EQ(Texlume("synth --engine graphcut --mesh " + scene +
                        "/object/mesh.ply --sample-texel-size 0.01 --sample " +
                        (tmp / "tiny.png").string() + " --out " + (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("tiny.png"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
}

// Graph-cut quilting with a BTF sample (issue 32): the capture factorised, its
// geometry maps matched, a BTF model folder that `texlume render` draws as a
// BTF; a capture missing an image is an input error naming it.
TEST(Cli, SynthGraphcutQuiltsABtfIntoABtfModelFolder) {
  TempDir tmp;
  const std::string scene = WriteColourSampleScene(tmp, 40);
  const std::string inputs = " --engine graphcut --mesh " + scene +
                             "/object/mesh.ply --atlas-size 512 --work-patch 8 --components 8 "
                             "--no-report";
  std::string out;
  ASSERT_EQ(Texlume("synth" + inputs + " --btf " + scene + "/material/btf --out " +
                        (tmp / "model").string(),
                    &out),
            0)
      << out;
  const nlohmann::json manifest =
      nlohmann::json::parse(testing::ReadText(tmp / "model/manifest.json"));
  EXPECT_EQ(manifest["summary"]["sample_kind"], "BTF");
  EXPECT_EQ(manifest["settings"]["sample_texel_size"], 0.01);  // the capture's own
  EXPECT_EQ(manifest["btf"]["format"], "texlume-btf-model-1");
  EXPECT_GT(manifest["summary"]["patches"].get<int>(), 1);
  EXPECT_TRUE(std::filesystem::exists(tmp / "model/btf/btf_svd.json"));
  EXPECT_TRUE(std::filesystem::exists(tmp / "model/btf_atlas_0.exr"));
  nlohmann::json render;
  ASSERT_EQ(RenderHeldOut(tmp, scene, &out, &render), 0) << out;
  EXPECT_EQ(render["settings"]["mode"], "btf");
  EXPECT_GT(render["metrics"]["mean_psnr_db"].get<double>(), 10.0);
  // The same folder given as --sample; a capture missing an image: refused, naming it.
  std::filesystem::remove(scene + "/material/btf/view_00_light_03.png");
  EXPECT_EQ(Texlume("synth" + inputs + " --sample " + scene + "/material/btf --out " +
                        (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("view_00_light_03.png"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(tmp / "bad"));
  // --btf naming a file: an input error naming it (1).
  EXPECT_EQ(Texlume("synth" + inputs + " --btf " + scene + "/object/mesh.ply --out " +
                        (tmp / "bad").string(),
                    &out),
            1);
  EXPECT_NE(out.find("is not a folder"), std::string::npos) << out;
  // --components with a sample that is no BTF: refused (2).
  EXPECT_EQ(Texlume("synth" + inputs + " --sample-texel-size 0.01 --sample " + scene +
                        "/material/capture/rti_005.png --out " + (tmp / "bad").string(),
                    &out),
            2);
}

}  // namespace
}  // namespace texlume
