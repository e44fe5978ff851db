#include "core/provenance.h"

#include <zlib.h>

#include <cstdio>
#include <fstream>
#include <vector>

#include "core/errors.h"

namespace texlume {
namespace {

std::string& CommandLineStore() {
  static std::string line;
  return line;
}

std::string Quoted(const std::string& arg) {
  if (!arg.empty() && arg.find_first_of(" \t\"'\\$") == std::string::npos) return arg;
  std::string out = "'";
  for (char c : arg) {
    if (c == '\'')
      out.append("'\\''");
    else
      out.push_back(c);
  }
  out.push_back('\'');
  return out;
}

}  // namespace

const char* TexlumeVersion() { return TEXLUME_VERSION; }

void RecordCommandLine(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    if (i > 0) line.push_back(' ');
    line.append(Quoted(argv[i] ? argv[i] : ""));
  }
  CommandLineStore() = line;
}

const std::string& RecordedCommandLine() { return CommandLineStore(); }

std::string FileCrc32(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot be read for its checksum");
  uLong crc = crc32(0L, Z_NULL, 0);
  std::vector<char> block(1 << 16);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    const std::streamsize got = in.gcount();
    if (got > 0)
      crc = crc32(crc, reinterpret_cast<const Bytef*>(block.data()), static_cast<uInt>(got));
  }
  if (in.bad()) throw InputError(path.string(), "cannot be read for its checksum");
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08lx", static_cast<unsigned long>(crc));
  return hex;
}

}  // namespace texlume
