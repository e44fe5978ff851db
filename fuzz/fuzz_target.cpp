// One libFuzzer target per parser (docs/robustness.md, "Fuzzing"). Each
// executable is this file compiled with TEXLUME_FUZZ_TARGET naming its parser
// (fuzz/fuzz_inputs.h). A parser may refuse its input with InputError (that is
// what it is for); any other exception, a crash, a leak, undefined behaviour
// (UBSan) or a memory error (AddressSanitizer) is a finding.
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string_view>

#include "core/errors.h"
#include "fuzz/fuzz_inputs.h"

#ifndef TEXLUME_FUZZ_TARGET
#error "compile with -DTEXLUME_FUZZ_TARGET=<parser name>"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    texlume::fuzz::ParseInput(TEXLUME_FUZZ_TARGET, bytes);
  } catch (const texlume::InputError&) {
    // A refusal naming the file: what a parser is for.
  } catch (const std::exception& e) {
    std::cerr << "texlume fuzz: " << TEXLUME_FUZZ_TARGET
              << " threw a non-InputError exception: " << e.what() << "\n";
    std::abort();
  }
  return 0;
}
