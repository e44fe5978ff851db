#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace texlume::fuzz {

/// The fuzz targets, one per parser (docs/robustness.md, "Fuzzing").
const std::vector<std::string>& Targets();

/// Runs the parser of `target` on `bytes` (parsers that read by path get them as a
/// file in a scratch folder of this process). A parser refuses bad bytes with
/// InputError; anything else it throws is a finding. Throws std::invalid_argument
/// for an unknown target.
void ParseInput(std::string_view target, std::string_view bytes);

}  // namespace texlume::fuzz
