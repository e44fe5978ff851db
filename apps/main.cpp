// texlume: one program, one subcommand per pipeline step (apps/cli.h).
#include <iostream>

#include "apps/cli.h"
#include "core/memory_budget.h"
#include "core/partial_output.h"
#ifdef TEXLUME_MPI
#include "distributed/mpi_ranks.h"
#endif

int main(int argc, char** argv) {
  // Before any thread starts: the allocator's settings, then SIGINT and SIGTERM
  // remove partial outputs, then exit.
  texlume::KeepFreedMemoryForReuse();
  texlume::InstallInterruptCleanup();
#ifdef TEXLUME_MPI
  // `mpirun -np N texlume synth ...`: MPI for the whole run; a rank that fails ends
  // them all, so none waits for it.
  texlume::distributed::MpiSession mpi(argc, argv, texlume::apps::LaunchedAsSeveralRanks());
  texlume::apps::SetRanks(mpi.ranks());
  const int exit_code = texlume::apps::RunTexlume(argc, argv, std::cout, std::cerr);
  if (exit_code != 0 && mpi.ranks()) {
    std::cout.flush(), std::cerr.flush();
    mpi.Abort(exit_code);
  }
  return exit_code;
#else
  return texlume::apps::RunTexlume(argc, argv, std::cout, std::cerr);
#endif
}
