#include "core/file_util.h"

#include <unistd.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "core/errors.h"
#include "core/partial_output.h"

namespace texlume {

void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write, bool binary) {
  const std::filesystem::path tmp = TemporaryPathOf(path);
  RemoveStalePartials(path);
  RegisterPartial(tmp);
  try {
    {
      std::ofstream out(tmp, binary ? std::ios::binary | std::ios::trunc : std::ios::trunc);
      if (!out) throw std::runtime_error(path.string() + ": cannot open for writing");
      write(out);
      out.flush();
      if (!out) throw std::runtime_error(path.string() + ": write failed (disk full?)");
    }
    std::filesystem::rename(tmp, path);
    ForgetPartial(tmp);
  } catch (...) {
    ForgetPartial(tmp);
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

void RequireWritableFilePath(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path folder = path.parent_path().empty() ? "." : path.parent_path();
  if (!std::filesystem::is_directory(folder, ec)) {
    throw InputError(path.string(),
                     "cannot be written: the folder " + folder.string() + " does not exist");
  }
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(path.string(), "is a folder; expected the name of a file to write");
  }
}

std::ifstream OpenForReading(const std::filesystem::path& path, bool binary) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path.string(), "file not found");
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(path.string(), "is a directory, expected a file");
  }
  std::ifstream in(path, binary ? std::ios::binary : std::ios::in);
  if (!in) throw InputError(path.string(), "cannot open for reading");
  return in;
}

std::string ContainedNameProblem(std::string_view name) {
  if (name.empty()) return "is empty";
  if (name.find('\0') != std::string_view::npos) return "holds a NUL character";
  if (name.find('\\') != std::string_view::npos) return "holds a backslash; use '/'";
  const std::filesystem::path relative(name);
  if (relative.has_root_path()) return "is an absolute path; it must name a file inside its folder";
  for (const auto& part : relative) {
    if (part == "..") return "leaves its folder (a '..' component)";
  }
  return {};
}

std::filesystem::path ContainedPath(const std::filesystem::path& folder, std::string_view name,
                                    const std::string& label, std::string_view what) {
  const std::string problem = ContainedNameProblem(name);
  if (!problem.empty()) {
    throw InputError(label, std::string(what) + " '" + std::string(name) + "' " + problem);
  }
  return folder / std::filesystem::path(name);
}

std::string LowerCase(std::string_view text) {
  std::string s(text);
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string LowerCaseExtension(const std::filesystem::path& path) {
  return LowerCase(path.extension().string());
}

std::string ReadFileBytes(const std::filesystem::path& path, std::uint64_t max_bytes) {
  std::ifstream in = OpenForReading(path, true);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path.string(), "cannot measure the file's size");
  if (static_cast<std::uint64_t>(size) > max_bytes) {
    throw InputError(path.string(), "is " + std::to_string(size) +
                                        " bytes, more than the limit of " +
                                        std::to_string(max_bytes));
  }
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in.read(bytes.data(), size)) throw InputError(path.string(), "cannot read the file");
  return bytes;
}

BinaryReader::BinaryReader(std::istream& in, std::string label)
    : in_(in), label_(std::move(label)) {
  const std::streampos start = in_.tellg();
  in_.seekg(0, std::ios::end);
  const std::streampos end = in_.tellg();
  in_.seekg(start);
  if (start < 0 || end < start || !in_) throw InputError(label_, "cannot determine file size");
  size_ = static_cast<std::uint64_t>(end - start);
}

void BinaryReader::ReadBytes(unsigned char* out, std::size_t n, std::string_view what) {
  if (remaining() < n) {
    throw InputError(label_, "truncated: " + std::string(what) + " needs " + std::to_string(n) +
                                 " bytes at offset " + std::to_string(offset_) + " but only " +
                                 std::to_string(remaining()) + " remain");
  }
  in_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
  if (!in_) throw InputError(label_, "read error at offset " + std::to_string(offset_));
  offset_ += n;
}

namespace {
template <typename U>
U FromLittleEndian(const unsigned char* b) {
  U v = 0;
  for (std::size_t i = 0; i < sizeof(U); ++i) v |= static_cast<U>(b[i]) << (8 * i);
  return v;
}
template <typename U>
void ToLittleEndian(U v, unsigned char* b) {
  for (std::size_t i = 0; i < sizeof(U); ++i) b[i] = static_cast<unsigned char>(v >> (8 * i));
}
}  // namespace

std::uint8_t BinaryReader::ReadU8() {
  unsigned char b[1];
  ReadBytes(b, 1, "a byte");
  return b[0];
}
std::uint32_t BinaryReader::ReadU32() {
  unsigned char b[4];
  ReadBytes(b, 4, "a uint32");
  return FromLittleEndian<std::uint32_t>(b);
}
std::int32_t BinaryReader::ReadI32() { return static_cast<std::int32_t>(ReadU32()); }
std::uint64_t BinaryReader::ReadU64() {
  unsigned char b[8];
  ReadBytes(b, 8, "a uint64");
  return FromLittleEndian<std::uint64_t>(b);
}
double BinaryReader::ReadF64() {
  unsigned char b[8];
  ReadBytes(b, 8, "a double");
  return std::bit_cast<double>(FromLittleEndian<std::uint64_t>(b));
}

std::string BinaryReader::ReadNulTerminatedString(std::string_view what) {
  std::string s;
  const std::uint64_t start = offset_;
  while (true) {
    if (remaining() == 0) {
      throw InputError(label_, std::string(what) + " starting at offset " + std::to_string(start) +
                                   " has no terminating NUL before the end of the file");
    }
    const char c = static_cast<char>(ReadU8());
    if (c == '\0') return s;
    s.push_back(c);
  }
}

void BinaryReader::CheckCount(std::uint64_t count, std::uint64_t min_item_bytes,
                              std::string_view what) {
  if (min_item_bytes > 0 && count > remaining() / min_item_bytes) {
    throw InputError(label_, "corrupt: " + std::string(what) + " count " + std::to_string(count) +
                                 " at offset " + std::to_string(offset_) + " needs at least " +
                                 std::to_string(min_item_bytes) + " bytes each but only " +
                                 std::to_string(remaining()) + " bytes remain");
  }
}

void BinaryReader::ExpectEnd() {
  if (remaining() != 0) {
    throw InputError(label_, "corrupt: " + std::to_string(remaining()) +
                                 " unexpected bytes after the last record at offset " +
                                 std::to_string(offset_));
  }
}

void WriteU8(std::ostream& out, std::uint8_t v) { out.put(static_cast<char>(v)); }
void WriteU32(std::ostream& out, std::uint32_t v) {
  unsigned char b[4];
  ToLittleEndian(v, b);
  out.write(reinterpret_cast<const char*>(b), 4);
}
void WriteI32(std::ostream& out, std::int32_t v) { WriteU32(out, static_cast<std::uint32_t>(v)); }
void WriteU64(std::ostream& out, std::uint64_t v) {
  unsigned char b[8];
  ToLittleEndian(v, b);
  out.write(reinterpret_cast<const char*>(b), 8);
}
void WriteF64(std::ostream& out, double v) { WriteU64(out, std::bit_cast<std::uint64_t>(v)); }

std::vector<std::string_view> SplitWhitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

std::uint64_t ParseUnsigned(std::string_view token, std::string_view what, const std::string& file,
                            std::size_t line) {
  std::uint64_t v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ec != std::errc() || ptr != token.data() + token.size()) {
    throw InputError(file,
                     "expected a non-negative integer for " + std::string(what) + ", got '" +
                         std::string(token) + "'",
                     line);
  }
  return v;
}

std::int64_t ParseSigned(std::string_view token, std::string_view what, const std::string& file,
                         std::size_t line) {
  std::int64_t v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ec != std::errc() || ptr != token.data() + token.size()) {
    throw InputError(
        file, "expected an integer for " + std::string(what) + ", got '" + std::string(token) + "'",
        line);
  }
  return v;
}

double ParseDouble(std::string_view token, std::string_view what, const std::string& file,
                   std::size_t line) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);  // "+1.5"
  double v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(v)) {
    throw InputError(
        file,
        "expected a finite number for " + std::string(what) + ", got '" + std::string(token) + "'",
        line);
  }
  return v;
}

}  // namespace texlume
