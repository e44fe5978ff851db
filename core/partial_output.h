#pragma once

#include <filesystem>
#include <string>

namespace texlume {

/// An output (a file or a folder) written under a temporary sibling name,
/// "<name>.texlume-partial-<pid>", and renamed to its final name only when complete, so
/// nothing that looks like a finished output ever holds half a result.
///
/// Until Commit(), the partial is registered: the destructor removes it (an
/// exception unwinding the job), and so does SIGINT or SIGTERM once
/// InstallInterruptCleanup() has run. A partial left behind by SIGKILL or a power
/// cut is removed by the next PartialOutput of the same final name
/// (RemoveStalePartials).
class PartialOutput {
 public:
  enum class Kind { kFile, kFolder };

  /// Removes stale partials of `final_path`, then (kFolder) creates the empty
  /// partial folder. Throws std::runtime_error naming the path when it cannot.
  PartialOutput(std::filesystem::path final_path, Kind kind);
  ~PartialOutput();
  PartialOutput(const PartialOutput&) = delete;
  PartialOutput& operator=(const PartialOutput&) = delete;

  /// Where to write: the partial's path.
  const std::filesystem::path& path() const { return partial_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }

  /// Renames the partial to the final path, replacing what was there (a folder
  /// is replaced whole). Atomic for a file; for a folder the old one is moved
  /// aside first and removed after. Throws std::runtime_error when it cannot.
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path partial_path_;
  bool committed_ = false;
};

/// Refuses (InputError naming `dir`) to replace a folder that exists, is not
/// empty and does not hold `marker`, the file that `kind` (for example "a texlume
/// render folder") always writes: a user's other files are never replaced.
void RequireReplaceableFolder(const std::filesystem::path& dir, const std::string& marker,
                              const std::string& kind);

/// "<name>.texlume-partial-<pid>" of this process, beside `final_path`.
std::filesystem::path PartialPathOf(const std::filesystem::path& final_path);

/// Removes the siblings "<name>.texlume-partial-<pid>", "<name>.texlume-tmp-<pid>"
/// and "<name>.texlume-old-<pid>" of `final_path` whose process no longer runs (left by SIGKILL, a
/// crash or a power cut). Partials of running processes are left alone.
void RemoveStalePartials(const std::filesystem::path& final_path);

/// Registers a temporary path to remove on SIGINT/SIGTERM (WriteFileAtomically's
/// temporary file); Forget() when it is renamed or removed.
void RegisterPartial(const std::filesystem::path& path);
void ForgetPartial(const std::filesystem::path& path);

/// Blocks SIGINT and SIGTERM in the calling thread (and so in every thread it
/// starts later) and starts a watcher thread that, on either signal, removes every
/// registered partial output and ends the process with 128 + the signal's number.
/// Call once, first thing in main(), before any other thread exists.
void InstallInterruptCleanup();

/// While `handler` is set (not null), SIGINT and SIGTERM call it (on the watcher
/// thread) instead of removing partials and ending the process: a server stops
/// serving and returns. Returns false when no watcher runs (InstallInterruptCleanup
/// was not called), in which case the caller installs its own signal handler.
bool SetInterruptHandler(void (*handler)(int));

/// "<path>.texlume-tmp-<pid>": the temporary name of a file written atomically.
std::filesystem::path TemporaryPathOf(const std::filesystem::path& path);

}  // namespace texlume
