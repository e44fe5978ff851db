// One libFuzzer target per parser (docs/robustness.md, "Fuzzing"): one executable,
// `fuzz_parsers`, linked once, under a name per parser (`fuzz_ply`, `fuzz_cameras_bin`,
// ...: links to it); the name it is run by picks the parser (fuzz/fuzz_inputs.h). A
// parser may refuse its input with InputError (that is what it is for); any other
// exception, a crash, a leak, undefined behaviour (UBSan) or a memory error
// (AddressSanitizer) is a finding.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <string>
#include <string_view>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "fuzz/fuzz_inputs.h"

namespace {

std::string g_target;  // the parser this run fuzzes

constexpr std::uint64_t kFuzzMemoryLimitBytes = std::uint64_t{4} << 20;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const std::string name = std::filesystem::path((*argv)[0]).filename().string();
  const std::string prefix = "fuzz_";
  g_target = name.starts_with(prefix) ? name.substr(prefix.size()) : name;
  const auto& targets = texlume::fuzz::Targets();
  if (std::find(targets.begin(), targets.end(), g_target) == targets.end()) {
    std::cerr << "texlume fuzz: run me as fuzz_<parser>, one of:";
    for (const std::string& t : targets) std::cerr << " fuzz_" << t;
    std::cerr << "\n";
    std::exit(2);
  }
  // A small memory limit, so that a header declaring a large image or mesh is refused
  // by the readers' estimates (RequireMemory) rather than allocated on every run. At 256 MiB
  // the PTM EXR target spent most of its time in AddressSanitizer's allocator, on the
  // buffers of such images (120 runs a second; about 280 at 4 MiB).
  texlume::SetMemoryLimitBytes(kFuzzMemoryLimitBytes);
  (void)argc;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    texlume::fuzz::ParseInput(g_target, bytes);
  } catch (const texlume::InputError&) {
    // A refusal naming the file: what a parser is for.
  } catch (const std::exception& e) {
    std::cerr << "texlume fuzz: " << g_target << " threw a non-InputError exception: " << e.what()
              << "\n";
    std::abort();
  }
  return 0;
}
