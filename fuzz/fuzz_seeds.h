#pragma once

#include <filesystem>

namespace texlume::fuzz {

/// Writes the seed corpus of every fuzz target into `out`/<target>/: small valid
/// files of each format, made by texlume's own writers and scene generator, so
/// that the fuzzers start from inputs that parse.
void WriteFuzzSeeds(const std::filesystem::path& out);

}  // namespace texlume::fuzz
