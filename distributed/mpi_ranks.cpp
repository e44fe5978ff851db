#include "distributed/mpi_ranks.h"

#include <mpi.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "core/check.h"

namespace texlume::distributed {
namespace {

// Messages go in pieces of at most 1 GiB (MPI counts are ints).
constexpr std::uint64_t kPieceBytes = std::uint64_t{1} << 30;
constexpr int kSizeTag = 1, kPieceTag = 2;

void Check(int status, const char* call) {
  TEXLUME_CHECK(status == MPI_SUCCESS, std::string(call) + " failed");
}

// The ranks of MPI_COMM_WORLD.
class MpiRanks final : public synth::RankCommunicator {
 public:
  MpiRanks() {
    Check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
    Check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
  }
  int Rank() const override { return rank_; }
  int Size() const override { return size_; }

  void Broadcast(std::vector<char>& bytes) override {
    std::uint64_t size = bytes.size();
    Check(MPI_Bcast(&size, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD), "MPI_Bcast");
    bytes.resize(size);
    for (std::uint64_t at = 0; at < size; at += kPieceBytes) {
      const int piece = static_cast<int>(std::min(kPieceBytes, size - at));
      Check(MPI_Bcast(bytes.data() + at, piece, MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
    }
  }

  void GatherToRoot(const std::vector<char>& bytes, const Receive& receive) override {
    if (rank_ != 0) {
      std::uint64_t size = bytes.size();
      Check(MPI_Send(&size, 1, MPI_UINT64_T, 0, kSizeTag, MPI_COMM_WORLD), "MPI_Send");
      for (std::uint64_t at = 0; at < size; at += kPieceBytes)
        Check(MPI_Send(bytes.data() + at, static_cast<int>(std::min(kPieceBytes, size - at)),
                       MPI_CHAR, 0, kPieceTag, MPI_COMM_WORLD),
              "MPI_Send");
      return;
    }
    for (int from = 1; from < size_; ++from) {
      std::uint64_t size = 0;
      Check(MPI_Recv(&size, 1, MPI_UINT64_T, from, kSizeTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
            "MPI_Recv");
      std::vector<char> message(size);
      for (std::uint64_t at = 0; at < size; at += kPieceBytes)
        Check(MPI_Recv(message.data() + at, static_cast<int>(std::min(kPieceBytes, size - at)),
                       MPI_CHAR, from, kPieceTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
              "MPI_Recv");
      receive(from, std::move(message));
    }
  }

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace

MpiSession::MpiSession(int& argc, char**& argv, bool start) {
  if (!start) return;
  int provided = 0;
  // Only the main thread calls MPI (OpenMP threads compute between the calls).
  Check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_FUNNELED) {
    MPI_Finalize();
    throw std::runtime_error(
        "this MPI library does not allow threads beside MPI (MPI_THREAD_FUNNELED)");
  }
  ranks_ = std::make_unique<MpiRanks>();
}

MpiSession::~MpiSession() {
  if (ranks_) MPI_Finalize();
}

void MpiSession::Abort(int exit_code) {
  if (ranks_) MPI_Abort(MPI_COMM_WORLD, exit_code);
  std::exit(exit_code);
}

}  // namespace texlume::distributed
