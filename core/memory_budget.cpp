#include "core/memory_budget.h"

#include <sys/resource.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/errors.h"

namespace texlume {
namespace {

std::atomic<std::uint64_t> g_limit_bytes{0};  // 0: the default
std::atomic<bool> g_limit_is_users{false};    // set by --memory-limit

// Three quarters of MemTotal, or 8 GiB when /proc/meminfo cannot be read.
std::uint64_t DefaultLimitBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemTotal:") return kib * 1024 / 4 * 3;
  }
  return std::uint64_t{8} << 30;
}

}  // namespace

std::uint64_t PeakResidentBytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024u;  // ru_maxrss is in KiB on Linux
}

std::uint64_t DefaultMemoryLimitBytes() {
  static const std::uint64_t default_limit = DefaultLimitBytes();
  return default_limit;
}

std::uint64_t MemoryLimitBytes() {
  const std::uint64_t set = g_limit_bytes.load();
  return set != 0 ? set : DefaultMemoryLimitBytes();
}

void SetMemoryLimitBytes(std::uint64_t bytes) {
  g_limit_bytes.store(bytes);
  g_limit_is_users.store(bytes != 0);
}

void SetSharedMemoryLimitBytes(std::uint64_t bytes) {
  g_limit_bytes.store(bytes);
  g_limit_is_users.store(false);
}

bool MemoryLimitIsUsers() { return g_limit_is_users.load(); }

std::uint64_t ParseMemorySize(const std::string& text) {
  const auto refuse = [&] {
    throw OptionError("--memory-limit '" + text + "' is not a memory size (bytes, or 512M, 8G)");
  };
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    refuse();
  }
  std::string unit = text.substr(used);
  for (char& c : unit) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() > 1 && (unit.ends_with("IB") || unit.ends_with("B"))) {
    unit = unit.substr(0, unit.find('I') != std::string::npos ? unit.find('I') : unit.size() - 1);
  }
  double scale = 1.0;
  if (unit == "K")
    scale = 1024.0;
  else if (unit == "M")
    scale = std::pow(1024.0, 2);
  else if (unit == "G")
    scale = std::pow(1024.0, 3);
  else if (unit == "T")
    scale = std::pow(1024.0, 4);
  else if (!unit.empty() && unit != "B")
    refuse();
  const double bytes = value * scale;
  if (!(bytes >= 1.0 && bytes <= std::ldexp(1.0, 60))) refuse();
  return static_cast<std::uint64_t>(bytes);
}

std::string MemorySizeText(double bytes) {
  const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 6) {
    bytes /= 1024.0;
    ++u;
  }
  char text[64];
  std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.2f %s", bytes, units[u]);
  return text;
}

void RequireMemory(double estimated_bytes, const std::string& what, const std::string& label) {
  const double limit = static_cast<double>(MemoryLimitBytes());
  if (!(estimated_bytes <= limit)) {
    throw InputError(label, what + " needs about " + MemorySizeText(estimated_bytes) +
                                ", more than the memory limit of " + MemorySizeText(limit) +
                                " (--memory-limit)");
  }
}

void KeepFreedMemoryForReuse() {
#ifdef __GLIBC__
  // A fixed threshold also stops glibc's own adjustment of it. A refusal (a value
  // glibc does not take) leaves its defaults, which are correct, only slower.
  static_cast<void>(mallopt(M_MMAP_THRESHOLD, kLargestArenaBlock));
  static_cast<void>(mallopt(M_TRIM_THRESHOLD, kFreedBytesKept));
#endif
}

}  // namespace texlume
