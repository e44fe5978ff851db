#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "mesh/face_partition.h"

namespace texlume::synth {

/// How the ranks of one distributed synthesis talk (issue 33: `mpirun -np N
/// texlume synth`; the MPI implementation is distributed/mpi_ranks.h). Every
/// rank calls each method at the same point of the job, in the same order.
class RankCommunicator {
 public:
  virtual ~RankCommunicator() = default;
  virtual int Rank() const = 0;
  virtual int Size() const = 0;
  /// Rank 0's `bytes`, on every rank.
  virtual void Broadcast(std::vector<char>& bytes) = 0;
  /// Every other rank's `bytes` handed to `receive` at rank 0, one message at a
  /// time in rank order (so rank 0 holds one at once); the others send theirs.
  using Receive = std::function<void(int rank, std::vector<char>&& bytes)>;
  virtual void GatherToRoot(const std::vector<char>& bytes, const Receive& receive) = 0;
};

/// What one rank of a distributed synthesis did (the run's timings).
struct RankRecord {
  int rank = 0;
  std::uint64_t faces = 0;          ///< faces of its region, border included
  std::uint64_t faces_placed = 0;   ///< its region's faces off the border, which it placed
  double seconds_prepare = 0.0;     ///< set-up, frames and photometry (sent by rank 0)
  double seconds_region = 0.0;      ///< placing and correcting them
  double seconds_finish = 0.0;      ///< their pass after placement (detail transfer)
  std::uint64_t bytes_sent = 0;     ///< what it sent rank 0
  double patch_memory_bytes = 0.0;  ///< the patches it holds were estimated to need
  /// Its resident memory's peak when its region was done (rank 0: before it gathers).
  std::uint64_t peak_resident_bytes = 0;
};

/// A distributed synthesis: the ranks and one region of faces per rank. Rank 0
/// places the faces on region borders first, breadth first along the borders,
/// and sends them to every rank; each rank places the faces of its region off
/// the border, breadth first from the borders; rank 0 gathers them.
struct FaceRegions {
  RankCommunicator* ranks = nullptr;  ///< Size() == partition.num_regions
  mesh::FacePartition partition;
};

/// The faces rank 0 places before the regions (BordersPlacedFirst): the region borders
/// (partition.on_border) and the faces with an edge neighbour on one. Placed together,
/// breadth first as one process places any face, the borders' own edges and the edges
/// next to them are as seamless as one process's; each region then grows from this
/// band. (The borders alone, a region's first faces each fitted to one border face,
/// left the edges next to the borders 19 % above one process's on 4 ranks.)
std::vector<char> BordersPlacedFirst(const mesh::FacePartition& partition,
                                     const std::vector<std::array<int, 3>>& neighbours);

/// The faces divided into `num_regions` regions of equal face counts
/// (mesh::PartitionFaces). Every face weighs the same: measured by
/// bench/mpi_bench.sh on a 20328-face column, a face's work (placement and detail
/// transfer) hardly depends on its views; weighting faces by 1 + their views (up
/// to 4) left the slower rank 9 % above the mean, equal weights 4 %.
mesh::FacePartition RegionsForRanks(const std::vector<std::array<int, 3>>& neighbours,
                                    int num_regions, std::uint32_t seed);

}  // namespace texlume::synth
