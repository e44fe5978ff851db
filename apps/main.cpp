// texlume: one program, one subcommand per pipeline step (apps/cli.h).
#include <iostream>

#include "apps/cli.h"
#include "core/partial_output.h"

int main(int argc, char** argv) {
  // Before any thread starts: SIGINT and SIGTERM remove partial outputs, then exit.
  texlume::InstallInterruptCleanup();
  return texlume::apps::RunTexlume(argc, argv, std::cout, std::cerr);
}
