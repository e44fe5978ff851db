#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

namespace texlume {

/// Parses a JSON file. Throws InputError naming it when it cannot be opened or
/// is not valid JSON.
nlohmann::json ReadJsonFile(const std::filesystem::path& path);

}  // namespace texlume
