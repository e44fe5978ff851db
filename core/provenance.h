#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace texlume {

/// texlume's version (the CMake project's).
const char* TexlumeVersion();

/// The command line of this process, as the program recorded it at start (RunTexlume);
/// empty when texlume runs as a library. Arguments with spaces or quotes are quoted.
void RecordCommandLine(int argc, const char* const* argv);
const std::string& RecordedCommandLine();

/// CRC-32 (ISO-HDLC, zlib's) of a file's bytes, read in blocks, as 8 hex digits; throws
/// InputError naming the file when it cannot be read.
std::string FileCrc32(const std::filesystem::path& path);

}  // namespace texlume
