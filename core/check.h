#pragma once

#include <stdexcept>
#include <string>

namespace texlume {

/// A broken internal invariant: a programming error in texlume, never bad input
/// (InputError) or a bad command line (OptionError). The program reports it as
/// an internal error (exit code 3).
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// Throws InternalError naming the condition, the source file and line.
[[noreturn]] void FailCheck(const char* condition, const char* file, int line,
                            const std::string& message);

}  // namespace texlume

/// Checks an internal invariant (a precondition a caller inside texlume must
/// meet): TEXLUME_CHECK(planes.size() == names.size(), "one name per plane").
#define TEXLUME_CHECK(condition, message)                                              \
  do {                                                                                 \
    if (!(condition)) ::texlume::FailCheck(#condition, __FILE__, __LINE__, (message)); \
  } while (false)
