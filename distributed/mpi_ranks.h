#pragma once

#include <memory>

#include "synth/face_regions.h"

namespace texlume::distributed {

/// MPI for the life of the program when `start` (it was launched as several
/// ranks: `mpirun -np N texlume synth ...`, issue 33, apps::LaunchedAsSeveralRanks);
/// otherwise nothing is started and ranks() is null. Built only with MPI (TEXLUME_MPI).
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv, bool start);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  /// The ranks of this job (MPI_COMM_WORLD); null in one process.
  synth::RankCommunicator* ranks() { return ranks_.get(); }
  /// Ends every rank with `exit_code` (a rank that failed must not leave the
  /// others waiting for it).
  [[noreturn]] void Abort(int exit_code);

 private:
  std::unique_ptr<synth::RankCommunicator> ranks_;
};

}  // namespace texlume::distributed
