#include "core/json_io.h"

#include <fstream>
#include <string>

#include "core/errors.h"
#include "core/file_util.h"

namespace texlume {

nlohmann::json ReadJsonFile(const std::filesystem::path& path) {
  std::ifstream in = OpenForReading(path, false);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string(), std::string("is not valid JSON: ") + e.what());
  }
}

}  // namespace texlume
