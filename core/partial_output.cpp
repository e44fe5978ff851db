#include "core/partial_output.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/errors.h"

namespace texlume {
namespace fs = std::filesystem;
namespace {

constexpr const char* kPartialTag = ".texlume-partial-";
constexpr const char* kTemporaryTag = ".texlume-tmp-";
constexpr const char* kAsideTag = ".texlume-old-";

// The partial outputs of this process not yet committed. The watcher thread
// removes them under the same lock a Commit() renames under, so an output is
// either whole under its final name or gone.
struct Registry {
  std::mutex mutex;
  std::set<fs::path> paths;
  void (*handler)(int) = nullptr;  // SetInterruptHandler's, instead of ending the process
  bool watching = false;
};
Registry& Partials() {
  static Registry registry;
  return registry;
}

// The process id in "<name><tag><pid>" for one of texlume's tags, or in
// "<stem><tag><pid><extension>" (an EXR's temporary, WriteExr), or 0.
pid_t PidOfSibling(const std::string& sibling, const fs::path& name) {
  const std::pair<std::string, std::string> forms[] = {
      {name.string(), ""}, {name.stem().string(), name.extension().string()}};
  for (const auto& [head, tail] : forms) {
    for (const std::string tag : {kPartialTag, kTemporaryTag, kAsideTag}) {
      const std::string prefix = head + tag;
      if (sibling.size() <= prefix.size() + tail.size() || !sibling.starts_with(prefix) ||
          !sibling.ends_with(tail))
        continue;
      pid_t pid = 0;
      const char* begin = sibling.data() + prefix.size();
      const char* end = sibling.data() + sibling.size() - tail.size();
      const auto [ptr, ec] = std::from_chars(begin, end, pid);
      if (ec == std::errc() && ptr == end && pid > 0) return pid;
    }
  }
  return 0;
}

// True while process `pid` exists and is not a zombie (killed, not yet reaped).
bool ProcessRuns(pid_t pid) {
  if (::kill(pid, 0) != 0 && errno != EPERM) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;  // no /proc: trust kill()
  const std::size_t close = line.rfind(')');   // "pid (comm) state ..."
  if (close == std::string::npos || close + 2 >= line.size()) return true;
  const char state = line[close + 2];
  return state != 'Z' && state != 'X';
}

void WatchForInterrupt(sigset_t signals) {
  int signal_number = 0;
  while (true) {
    if (::sigwait(&signals, &signal_number) != 0) continue;
    std::lock_guard<std::mutex> lock(Partials().mutex);
    if (Partials().handler != nullptr) {
      Partials().handler(signal_number);
      continue;
    }
    // Other threads may still be writing into a partial folder: a few tries.
    for (const fs::path& p : Partials().paths) {
      for (int attempt = 0; attempt < 5; ++attempt) {
        std::error_code ec;
        fs::remove_all(p, ec);
        if (!fs::exists(p, ec)) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
    static const char kMessage[] = "\ntexlume: interrupted; partial outputs removed\n";
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
    ::_exit(128 + signal_number);
  }
}

}  // namespace

void RequireReplaceableFolder(const fs::path& dir, const std::string& marker,
                              const std::string& kind) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "exists and is not a folder");
  if (fs::is_empty(dir, ec) || fs::exists(dir / marker, ec)) return;
  throw InputError(dir.string(), "exists, is not empty and is not " + kind + " (it has no " +
                                     marker + "); not replacing it");
}

fs::path PartialPathOf(const fs::path& final_path) {
  fs::path p = final_path;
  if (!p.has_filename()) p = p.parent_path();  // "out/" names the folder "out"
  return p.parent_path() / (p.filename().string() + kPartialTag + std::to_string(::getpid()));
}

fs::path TemporaryPathOf(const fs::path& path) {
  fs::path tmp = path;
  tmp += kTemporaryTag + std::to_string(::getpid());
  return tmp;
}

void RemoveStalePartials(const fs::path& final_path) {
  fs::path p = final_path;
  if (!p.has_filename()) p = p.parent_path();
  const fs::path parent = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  const fs::path name = p.filename();
  // Inside a partial folder nothing is stale; it is not scanned once per file written.
  if (parent.string().find(kPartialTag) != std::string::npos) return;
  std::error_code ec;
  if (!fs::is_directory(parent, ec)) return;
  for (const auto& entry : fs::directory_iterator(parent, ec)) {
    const pid_t pid = PidOfSibling(entry.path().filename().string(), name);
    if (pid == 0 || pid == ::getpid() || ProcessRuns(pid)) continue;
    std::error_code remove_ec;
    fs::remove_all(entry.path(), remove_ec);
  }
}

void RegisterPartial(const fs::path& path) {
  std::lock_guard<std::mutex> lock(Partials().mutex);
  Partials().paths.insert(path);
}

void ForgetPartial(const fs::path& path) {
  std::lock_guard<std::mutex> lock(Partials().mutex);
  Partials().paths.erase(path);
}

PartialOutput::PartialOutput(fs::path final_path, Kind kind)
    : final_path_(std::move(final_path)), partial_path_(PartialPathOf(final_path_)) {
  if (!final_path_.has_filename()) final_path_ = final_path_.parent_path();
  RemoveStalePartials(final_path_);
  std::error_code ec;
  fs::remove_all(partial_path_, ec);
  RegisterPartial(partial_path_);
  if (kind == Kind::kFolder && !fs::create_directories(partial_path_, ec) && ec) {
    ForgetPartial(partial_path_);
    throw std::runtime_error(partial_path_.string() + ": cannot create the folder (" +
                             ec.message() + ")");
  }
}

PartialOutput::~PartialOutput() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(partial_path_, ec);
  ForgetPartial(partial_path_);
}

void PartialOutput::Commit() {
  std::unique_lock<std::mutex> lock(Partials().mutex);
  std::error_code ec;
  const bool replace_folder =
      fs::is_directory(final_path_, ec) && fs::is_directory(partial_path_, ec);
  fs::path aside;
  if (replace_folder) {
    aside = final_path_.parent_path() /
            (final_path_.filename().string() + kAsideTag + std::to_string(::getpid()));
    fs::remove_all(aside, ec);
    fs::rename(final_path_, aside, ec);
    if (ec) {
      throw std::runtime_error(final_path_.string() + ": cannot move the old output aside (" +
                               ec.message() + ")");
    }
  }
  fs::rename(partial_path_, final_path_, ec);
  if (ec) {
    if (replace_folder) fs::rename(aside, final_path_, ec);
    throw std::runtime_error(final_path_.string() +
                             ": cannot rename the finished output into place");
  }
  Partials().paths.erase(partial_path_);
  committed_ = true;
  lock.unlock();
  if (replace_folder) fs::remove_all(aside, ec);
}

void InstallInterruptCleanup() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  if (::pthread_sigmask(SIG_BLOCK, &signals, nullptr) != 0) return;
  std::thread(WatchForInterrupt, signals).detach();
  std::lock_guard<std::mutex> lock(Partials().mutex);
  Partials().watching = true;
}

bool SetInterruptHandler(void (*handler)(int)) {
  std::lock_guard<std::mutex> lock(Partials().mutex);
  Partials().handler = handler;
  return Partials().watching;
}

}  // namespace texlume
