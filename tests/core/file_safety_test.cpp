// Files named by other files stay inside their folder (ContainedPath), whole
// files are read within a limit (ReadFileBytes), and outputs are written under a
// partial name that is renamed when complete or removed (PartialOutput).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdlib>

#include "core/errors.h"
#include "core/file_util.h"
#include "core/memory_budget.h"
#include "core/partial_output.h"
#include "tests/test_util.h"

namespace texlume {
namespace {

namespace fs = std::filesystem;
using testing::InputErrorMessage;
using testing::TempDir;
using testing::WriteText;

TEST(ContainedPath, RefusesNamesThatLeaveTheFolder) {
  const fs::path folder = "/models/a";
  EXPECT_EQ(ContainedPath(folder, "ptm_atlas_0.exr", "manifest.json", "exr"),
            folder / "ptm_atlas_0.exr");
  EXPECT_EQ(ContainedPath(folder, "sub/x.png", "manifest.json", "exr"), folder / "sub/x.png");
  const std::vector<std::string> bad_names = {
      "../../../../etc/passwd", "/etc/passwd", "a/../../b", "..", "", "a\\..\\b",
      std::string("a\0b", 3)};
  for (const std::string& bad : bad_names) {
    const std::string message =
        InputErrorMessage([&] { ContainedPath(folder, bad, "manifest.json", "exr"); });
    EXPECT_EQ(message.rfind("manifest.json: exr", 0), 0u) << bad << " -> " << message;
  }
}

TEST(ReadFileBytes, ReadsWholeFilesAndRefusesMoreThanTheLimit) {
  TempDir tmp;
  WriteText(tmp / "f.bin", std::string("ab\0cd", 5));
  EXPECT_EQ(ReadFileBytes(tmp / "f.bin", 5), std::string("ab\0cd", 5));
  EXPECT_NE(InputErrorMessage([&] { ReadFileBytes(tmp / "f.bin", 4); }).find("more than"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([&] { ReadFileBytes(tmp / "none", 4); }).find("none"),
            std::string::npos);
}

TEST(RequireWritableFilePath, RefusesAMissingFolderAndAFolderNameBeforeAnyWork) {
  TempDir tmp;
  RequireWritableFilePath(tmp / "out.ptm");
  RequireWritableFilePath("relative.ptm");  // the working folder
  const std::string missing =
      InputErrorMessage([&] { RequireWritableFilePath(tmp / "no/out.ptm"); });
  EXPECT_NE(missing.find("the folder " + (tmp / "no").string() + " does not exist"),
            std::string::npos)
      << missing;
  fs::create_directories(tmp / "dir");
  EXPECT_NE(InputErrorMessage([&] { RequireWritableFilePath(tmp / "dir"); }).find("is a folder"),
            std::string::npos);
}

TEST(PartialOutput, CommitRenamesAndReplacesAFolderWhole) {
  TempDir tmp;
  const fs::path out = tmp / "out";
  fs::create_directories(out / "old");
  {
    PartialOutput partial(out, PartialOutput::Kind::kFolder);
    EXPECT_EQ(partial.path().filename().string(),
              "out.texlume-partial-" + std::to_string(::getpid()));
    WriteText(partial.path() / "result.json", "{}");
    EXPECT_FALSE(fs::exists(out / "result.json"));
    partial.Commit();
  }
  EXPECT_TRUE(fs::exists(out / "result.json"));
  EXPECT_FALSE(fs::exists(out / "old"));
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(PartialOutput, AnUncommittedOutputIsRemoved) {
  TempDir tmp;
  try {
    PartialOutput partial(tmp / "out", PartialOutput::Kind::kFolder);
    WriteText(partial.path() / "half.png", "x");
    throw std::runtime_error("the job failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_TRUE(fs::is_empty(tmp.path()));
}

TEST(PartialOutput, StalePartialsOfDeadProcessesAreRemoved) {
  TempDir tmp;
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);  // a process id that no longer runs
  const std::string dead = std::to_string(child);
  fs::create_directories(tmp / ("out.exr.texlume-partial-" + dead));
  WriteText(tmp / ("out.exr.texlume-tmp-" + dead), "x");
  WriteText(tmp / ("out.texlume-tmp-" + dead + ".exr"), "x");  // WriteExr's temporary
  fs::create_directories(tmp / "out.exr.texlume-partial-1");   // process 1 runs: left alone
  fs::create_directories(tmp / ("other.texlume-partial-" + dead));
  fs::create_directories(tmp / ("out.exr.old-" + dead));  // a user's backup: not texlume's
  RemoveStalePartials(tmp / "out.exr");
  EXPECT_FALSE(fs::exists(tmp / ("out.exr.texlume-partial-" + dead)));
  EXPECT_FALSE(fs::exists(tmp / ("out.exr.texlume-tmp-" + dead)));
  EXPECT_FALSE(fs::exists(tmp / ("out.texlume-tmp-" + dead + ".exr")));
  EXPECT_TRUE(fs::exists(tmp / "out.exr.texlume-partial-1"));
  EXPECT_TRUE(fs::exists(tmp / ("other.texlume-partial-" + dead)));
  EXPECT_TRUE(fs::exists(tmp / ("out.exr.old-" + dead)));
}

TEST(PartialOutput, RequireReplaceableFolderKeepsAUsersFiles) {
  TempDir tmp;
  EXPECT_NO_THROW(RequireReplaceableFolder(tmp / "absent", "render.json", "a render folder"));
  EXPECT_NO_THROW(RequireReplaceableFolder(tmp.path(), "render.json", "a render folder"));
  WriteText(tmp / "thesis.tex", "x");
  EXPECT_NE(InputErrorMessage([&] {
              RequireReplaceableFolder(tmp.path(), "render.json", "a render folder");
            }).find("not replacing"),
            std::string::npos);
  WriteText(tmp / "render.json", "{}");
  EXPECT_NO_THROW(RequireReplaceableFolder(tmp.path(), "render.json", "a render folder"));
}

TEST(MemoryBudget, ParsesSizesWithBinaryUnits) {
  EXPECT_EQ(ParseMemorySize("2000000000"), 2000000000u);
  EXPECT_EQ(ParseMemorySize("512M"), 512u << 20);
  EXPECT_EQ(ParseMemorySize("1.5GiB"), 3u << 29);
  EXPECT_EQ(ParseMemorySize("8gb"), std::uint64_t{8} << 30);
  for (const std::string bad : {"", "G", "12Q", "-1G", "0", "nan", "1e30T"}) {
    EXPECT_THROW(ParseMemorySize(bad), OptionError) << bad;
  }
  EXPECT_EQ(MemorySizeText(1536.0 * (1 << 20)), "1.50 GiB");
}

TEST(MemoryBudget, RefusesAnEstimateOverTheLimitNamingTheFile) {
  SetMemoryLimitBytes(1 << 20);
  EXPECT_NO_THROW(RequireMemory(1 << 19, "half of it", "a.png"));
  const std::string message =
      InputErrorMessage([] { RequireMemory(3 << 20, "reading the image", "a.png"); });
  SetMemoryLimitBytes(0);
  EXPECT_EQ(message,
            "a.png: reading the image needs about 3.00 MiB, more than the memory limit "
            "of 1.00 MiB (--memory-limit)");
  EXPECT_GT(MemoryLimitBytes(), std::uint64_t{1} << 28);  // the machine's: far more than 256 MiB
}

// AddressSanitizer brings its own allocator (GCC and clang say so differently).
#if defined(__SANITIZE_ADDRESS__)
#define TEXLUME_OWN_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TEXLUME_OWN_ALLOCATOR 1
#endif
#endif

#if defined(__GLIBC__) && !defined(TEXLUME_OWN_ALLOCATOR)
// In a child process (the settings stay there), from glibc's fixed defaults (so that
// what earlier tests freed does not matter): a 16 MiB buffer is mapped on its own;
// then, with the settings, it comes from the arena and stays there when freed, and
// one over kLargestArenaBlock is still mapped on its own.
TEST(MemoryBudget, FreedBuffersAreKeptForTheNextFace) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    mallopt(M_MMAP_THRESHOLD, 128 << 10);
    mallopt(M_TRIM_THRESHOLD, 128 << 10);
    // Used through volatile pointers, or the compiler drops the pairs.
    const auto is_mapped = [](std::size_t bytes, std::size_t* arena_after_free) {
      const std::size_t blocks = mallinfo2().hblks;
      char* volatile block = static_cast<char*>(std::malloc(bytes));
      block[0] = 1;
      const bool mapped = mallinfo2().hblks == blocks + 1;
      const std::size_t arena = mallinfo2().arena;
      std::free(block);
      if (arena_after_free) *arena_after_free = arena - mallinfo2().arena;  // bytes given back
      return mapped;
    };
    const bool mapped_by_default = is_mapped(16 << 20, nullptr);
    KeepFreedMemoryForReuse();
    std::size_t given_back = 1;
    const bool from_arena = !is_mapped(16 << 20, &given_back);
    const bool large_mapped = is_mapped(std::size_t{kLargestArenaBlock} + (16 << 20), nullptr);
    _exit((mapped_by_default ? 0 : 1) | (from_arena ? 0 : 2) | (given_back == 0 ? 0 : 4) |
          (large_mapped ? 0 : 8));
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0)
      << "1: not mapped by default, 2: not from the arena, 4: given back, 8: not mapped";
}
#endif

}  // namespace
}  // namespace texlume
