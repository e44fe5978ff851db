// A disk that fills up part way through a run (issue 30): `scene` and `synth` write
// into a small tmpfs mounted in a private mount namespace (`unshare --mount`, which
// needs root; the test is skipped, saying so, without it). Wherever the disk fills,
// from the first file to the last, the run must end with exit code 1, a message that
// names the file it could not write, and nothing left on the disk: no output folder
// and no partial.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_util.h"

namespace texlume {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;
using testing::TempDir;

const char kListingMarker[] = "--- left on the disk ---";

struct FullDiskRun {
  int exit_code = 0;
  std::string message;               // texlume's output
  std::vector<std::string> entries;  // what the disk holds afterwards
};

// Runs `texlume ARGS` (which writes into `disk`) with a tmpfs of `kib` KiB mounted on
// `disk` for that run only.
FullDiskRun RunOnSmallDisk(const fs::path& disk, int kib, const std::string& args) {
  fs::create_directories(disk);
  const std::string script = "mount -t tmpfs -o size=" + std::to_string(kib) + "k tmpfs " +
                             disk.string() + " || exit 99; " + TEXLUME_BINARY + " " + args +
                             " 2>&1; code=\\$?; echo '" + kListingMarker + "'; cd " +
                             disk.string() + " && find . -mindepth 1; exit \\$code";
  FullDiskRun run;
  std::string out;
  run.exit_code = RunCommand("unshare --mount sh -c \"" + script + "\"", &out);
  const std::size_t marker = out.find(kListingMarker);
  run.message = out.substr(0, marker);
  if (marker != std::string::npos) {
    std::istringstream listing(out.substr(marker + sizeof kListingMarker));
    for (std::string line; std::getline(listing, line);) {
      if (!line.empty()) run.entries.push_back(line);
    }
  }
  return run;
}

bool CanMountPrivately() {
  std::string out;
  return ::geteuid() == 0 && RunCommand("unshare --mount true", &out) == 0;
}

// The KiB the output of `texlume ARGS` takes, written to an ordinary folder.
std::uintmax_t OutputKib(const fs::path& out_dir, const std::string& args) {
  std::string out;
  EXPECT_EQ(RunCommand(std::string(TEXLUME_BINARY) + " " + args, &out), 0) << out;
  std::uintmax_t bytes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(out_dir)) {
    if (entry.is_regular_file()) bytes += (entry.file_size() + 4095) / 4096 * 4096;
  }
  fs::remove_all(out_dir);
  return bytes / 1024;
}

// Fills the disk at a spread of points of the output, the last just short of all of it.
void ExpectCleanFailuresWhereverTheDiskFills(const fs::path& root, const std::string& command,
                                             const std::string& inputs) {
  const std::uintmax_t full_kib =
      OutputKib(root / "reference", command + " --out " + (root / "reference").string() + inputs);
  ASSERT_GT(full_kib, 64u);
  const fs::path disk = root / "disk";
  for (const double share : {0.1, 0.5, 0.95}) {
    const int kib = static_cast<int>(share * static_cast<double>(full_kib));
    const FullDiskRun run =
        RunOnSmallDisk(disk, kib, command + " --out " + (disk / "out").string() + inputs);
    SCOPED_TRACE(command + " on a disk of " + std::to_string(kib) + " KiB of " +
                 std::to_string(full_kib) + ": " + run.message);
    ASSERT_NE(run.exit_code, 99) << "mounting the tmpfs failed";
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.message.find((disk / "out").string()), std::string::npos);
    EXPECT_EQ(run.message.find("terminate called"), std::string::npos);
    EXPECT_TRUE(run.entries.empty()) << run.entries.size() << " entries, the first "
                                     << (run.entries.empty() ? "" : run.entries.front());
  }
}

TEST(FullDisk, SceneAndSynthFailCleanlyWhereverTheDiskFills) {
  if (!CanMountPrivately()) {
    GTEST_SKIP() << "needs root and `unshare --mount` to mount a small tmpfs";
  }
  TempDir tmp;
  const std::string scene_options =
      " --images 6 --width 96 --height 96 --capture-size 32 --capture-lights 8"
      " --held-out-lights 2 --held-out-views 1 --texel-size 0.01";
  ExpectCleanFailuresWhereverTheDiskFills(tmp.path(), "scene", scene_options);

  std::string out;
  const fs::path scene = tmp / "scene";
  ASSERT_EQ(
      RunCommand(std::string(TEXLUME_BINARY) + " scene --out " + scene.string() + scene_options,
                 &out),
      0)
      << out;
  const std::string object = scene.string() + "/object";
  const std::string synth_inputs =
      " --model " + object + "/sparse --images " + object + "/images --lights " + object +
      "/lights.json --mesh " + object + "/mesh.ply --sample " + scene.string() +
      "/material/capture/rti_005.png --sample-texel-size 0.01" + " --atlas-size 256";
  ExpectCleanFailuresWhereverTheDiskFills(tmp.path(), "synth", synth_inputs);
}

}  // namespace
}  // namespace texlume
