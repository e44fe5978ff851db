// Writes the seed corpus of every fuzz target (fuzz/fuzz_seeds.h) into OUT/<target>/.
// Run: fuzz_make_seeds OUT
#include <iostream>

#include "fuzz/fuzz_seeds.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: fuzz_make_seeds OUT\n";
    return 2;
  }
  texlume::fuzz::WriteFuzzSeeds(argv[1]);
  std::cout << "seeds written to " << argv[1] << "\n";
  return 0;
}
