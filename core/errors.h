#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace texlume {

/// Thrown when an input file (or stream) is malformed, missing or inconsistent.
/// what() reads "<file>:<line>: <message>" when a line is known, "<file>: <message>"
/// otherwise, so a user sees where the problem is without a debugger.
class InputError : public std::runtime_error {
 public:
  /// @param file  path (or stream label) of the offending input
  /// @param message  what is wrong, in words a user understands
  /// @param line  1-based line number, 0 when unknown or not a text format
  InputError(std::string file, const std::string& message, std::size_t line = 0)
      : std::runtime_error(Format(file, message, line)), file_(std::move(file)), line_(line) {}

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  static std::string Format(const std::string& file, const std::string& message, std::size_t line) {
    std::string out;
    out.append(file);
    if (line > 0) out.append(":").append(std::to_string(line));
    out.append(": ").append(message);
    return out;
  }
  std::string file_;
  std::size_t line_;
};

/// Thrown by an Options::Check() when a setting is out of its documented range.
class OptionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Throws OptionError "`what` must be in [lo, hi]" unless lo <= value <= hi
/// (NaN is refused).
inline void RequireInRange(double value, double lo, double hi, const std::string& what) {
  if (!(value >= lo && value <= hi))
    throw OptionError(what + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                      "]");
}

}  // namespace texlume
