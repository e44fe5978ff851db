#pragma once

#include <cstdint>
#include <string>

namespace texlume {

/// The memory one texlume run may use, in bytes (docs/robustness.md, "Memory"):
/// `--memory-limit`, or by default three quarters of the machine's physical memory
/// (MemTotal in /proc/meminfo; 8 GiB where that cannot be read).
std::uint64_t MemoryLimitBytes();
/// Sets the limit the user asked for (`--memory-limit`); 0 restores the default.
void SetMemoryLimitBytes(std::uint64_t bytes);
/// The default limit of this machine (three quarters of its memory), whatever is set.
std::uint64_t DefaultMemoryLimitBytes();
/// Sets this process's share of the machine's default limit (ranks of one job on
/// one machine share it; docs/robustness.md "Memory"): not the user's limit.
void SetSharedMemoryLimitBytes(std::uint64_t bytes);
/// Whether the limit is the user's (SetMemoryLimitBytes, not 0), not the default or
/// a share of it.
bool MemoryLimitIsUsers();

/// Parses a memory size: bytes ("2000000000") or a number with a binary unit
/// ("512M", "1.5G", "2T"; K, M, G, T are powers of 1024, a trailing "B" or "iB" is
/// allowed). Throws OptionError for anything else, zero or more than 2^60 bytes.
std::uint64_t ParseMemorySize(const std::string& text);

/// The most resident memory this process has used so far, in bytes (getrusage's
/// ru_maxrss): what a run's manifest records as its peak.
std::uint64_t PeakResidentBytes();

/// The most freed memory glibc's allocator keeps at the top of an arena, in bytes.
inline constexpr int kFreedBytesKept = 64 << 20;
/// The largest block it serves from its arenas (larger ones are mapped on their own):
/// 32 MiB, the most glibc accepts on a 64-bit system.
inline constexpr int kLargestArenaBlock = 32 << 20;
/// Called once at the start of the program, before any thread: the allocator keeps
/// up to kFreedBytesKept freed at the top of each arena and serves blocks up to
/// kLargestArenaBlock from its arenas, instead of giving each large buffer back to
/// the system when it is freed and faulting its pages in again when the next face
/// asks for one (issue 33: half the page faults and 10 % of the CPU of the s512
/// job; docs/robustness.md, "Memory"). Elsewhere than glibc, nothing.
void KeepFreedMemoryForReuse();

/// "1.50 GiB", "512 MiB", ...
std::string MemorySizeText(double bytes);

/// Before a large allocation: throws InputError naming `label` (the file whose
/// contents ask for it) when `estimated_bytes` exceed MemoryLimitBytes(), with the
/// estimate, what it is for and the limit, so a run is refused up front rather than
/// ended by the allocator.
void RequireMemory(double estimated_bytes, const std::string& what, const std::string& label);

}  // namespace texlume
