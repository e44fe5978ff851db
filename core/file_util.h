#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <istream>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace texlume {

/// Writes a file atomically: `write` fills a stream bound to a temporary file
/// next to `path`, which is renamed over `path` only when everything was written.
/// On failure the temporary file is removed and no partial output remains.
/// Throws std::runtime_error naming the file when it cannot be written.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write, bool binary);

/// Throws InputError naming `path` unless it can be written as a file: its folder
/// exists and `path` is not a folder. Jobs call it before their work, so that a
/// mistyped output path fails at once instead of after the work.
void RequireWritableFilePath(const std::filesystem::path& path);

/// Opens a file for reading; throws InputError naming it when it cannot be opened.
/// The returned stream throws nothing; readers check it themselves.
std::ifstream OpenForReading(const std::filesystem::path& path, bool binary);

/// The file `name`, read from the file `label` (a manifest, btf.json, ...), inside
/// `folder`. Throws InputError naming `label` and `what` unless `name` is a
/// non-empty relative path none of whose components is "..", so that no file can
/// send texlume outside its own folder.
std::filesystem::path ContainedPath(const std::filesystem::path& folder, std::string_view name,
                                    const std::string& label, std::string_view what);
/// Why `name` cannot name a file inside a folder (as ContainedPath refuses it), or
/// empty when it can.
std::string ContainedNameProblem(std::string_view name);

/// `text` with ASCII letters in lower case.
std::string LowerCase(std::string_view text);

/// The file's extension in lower case, with its dot (".ply"), or "".
std::string LowerCaseExtension(const std::filesystem::path& path);

/// Reads a whole file into memory; throws InputError naming it when it cannot be
/// read or holds more than `max_bytes` (checked before anything is allocated).
std::string ReadFileBytes(const std::filesystem::path& path, std::uint64_t max_bytes);

/// Bounded little-endian reader over a stream: every read and every count is
/// checked against the bytes left, so a corrupt file can never make the caller
/// allocate more than the file could hold. Errors are InputError with the label
/// and the byte offset.
class BinaryReader {
 public:
  /// @param in  stream positioned at the start of the data; its size is measured once
  /// @param label  file name used in error messages
  BinaryReader(std::istream& in, std::string label);

  std::uint8_t ReadU8();
  std::uint32_t ReadU32();
  std::int32_t ReadI32();
  std::uint64_t ReadU64();
  double ReadF64();
  /// Reads bytes up to and including a NUL; throws when no NUL comes before the end.
  std::string ReadNulTerminatedString(std::string_view what);
  /// Throws unless `count` items of at least `min_item_bytes` each fit in the bytes
  /// left. Call before reserving or resizing anything by `count`.
  void CheckCount(std::uint64_t count, std::uint64_t min_item_bytes, std::string_view what);
  /// Throws when bytes are left after the last record.
  void ExpectEnd();

  std::uint64_t offset() const { return offset_; }
  std::uint64_t remaining() const { return size_ - offset_; }
  const std::string& label() const { return label_; }

 private:
  void ReadBytes(unsigned char* out, std::size_t n, std::string_view what);
  std::istream& in_;
  std::string label_;
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
};

/// Little-endian writer helpers.
void WriteU8(std::ostream& out, std::uint8_t v);
void WriteU32(std::ostream& out, std::uint32_t v);
void WriteI32(std::ostream& out, std::int32_t v);
void WriteU64(std::ostream& out, std::uint64_t v);
void WriteF64(std::ostream& out, double v);

/// Splits a text line at runs of spaces and tabs (a trailing '\r' is dropped).
std::vector<std::string_view> SplitWhitespace(std::string_view line);

/// Strict number parsing of a whole token; throws InputError(file, message, line).
std::uint64_t ParseUnsigned(std::string_view token, std::string_view what, const std::string& file,
                            std::size_t line);
std::int64_t ParseSigned(std::string_view token, std::string_view what, const std::string& file,
                         std::size_t line);
double ParseDouble(std::string_view token, std::string_view what, const std::string& file,
                   std::size_t line);

}  // namespace texlume
