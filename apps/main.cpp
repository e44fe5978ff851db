// texlume: one program, one subcommand per pipeline step (apps/cli.h).
#include <iostream>

#include "apps/cli.h"

int main(int argc, char** argv) {
  return texlume::apps::RunTexlume(argc, argv, std::cout, std::cerr);
}
