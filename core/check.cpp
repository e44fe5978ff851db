#include "core/check.h"

#include <filesystem>

namespace texlume {

void FailCheck(const char* condition, const char* file, int line, const std::string& message) {
  throw InternalError(std::filesystem::path(file).filename().string() + ":" + std::to_string(line) +
                      ": " + message + " (" + condition + " is false)");
}

}  // namespace texlume
