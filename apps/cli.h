#pragma once

#include <ostream>

namespace texlume::synth {
class RankCommunicator;
}

namespace texlume::apps {

/// Exit codes of the texlume program.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInputError = 1;     ///< bad or missing input files, problems found
inline constexpr int kExitUsage = 2;          ///< bad command line
inline constexpr int kExitInternalError = 3;  ///< a broken internal invariant (a bug)

/// The texlume program: one subcommand per job. The command line is parsed by
/// CLI11 with every option bound to the job's Options (pipeline/jobs.h,
/// synth/pipeline.h), so `texlume SUB --help` lists each option with its
/// default and an unknown option is answered with the nearest one; the job
/// runs; errors map to the exit codes above (the message names the file for
/// bad input). Writes what a user reads to `out`, warnings and errors to `err`.
int RunTexlume(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

/// True when an MPI launcher started this process as one of several ranks
/// (OpenMPI's OMPI_COMM_WORLD_SIZE or MPICH's PMI_SIZE above 1).
bool LaunchedAsSeveralRanks();
/// The ranks an MPI launcher started on this machine (1 when it says nothing):
/// each takes this share of the default --memory-limit.
int RanksOnThisMachine();
/// The ranks of a distributed run, which main() started (distributed/mpi_ranks.h);
/// null in one process. Only `texlume synth` runs across ranks.
void SetRanks(synth::RankCommunicator* ranks);
synth::RankCommunicator* Ranks();

}  // namespace texlume::apps
