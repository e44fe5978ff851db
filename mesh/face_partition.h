#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace texlume::mesh {

/// The faces of a mesh divided into regions over edge adjacency (issue 33: one
/// region per rank of a distributed synthesis), by METIS's multilevel k-way
/// partition of the dual graph: regions of about equal weight whose shared
/// edges are few.
struct FacePartition {
  int num_regions = 1;
  std::vector<int> region_of_face;  ///< in [0, num_regions)
  /// 1 for a face with an edge neighbour in another region.
  std::vector<char> on_border;
  /// Faces per region, and border faces per region.
  std::vector<std::size_t> faces_in_region, border_faces_in_region;
  /// Edges whose two faces lie in different regions (METIS's edge cut).
  std::size_t cut_edges = 0;
};

/// Partitions the faces whose edge neighbours are `neighbours`
/// (mesh::FaceNeighbours) into `num_regions` regions of about equal summed
/// `face_weights` (empty: 1 each; each >= 1), with METIS's seed `seed`
/// (deterministic for a seed). One region, or fewer faces than regions, gives
/// region f mod num_regions. Throws std::invalid_argument for num_regions < 1
/// or weights of the wrong length or below 1.
FacePartition PartitionFaces(const std::vector<std::array<int, 3>>& neighbours, int num_regions,
                             const std::vector<std::int32_t>& face_weights = {},
                             std::uint32_t seed = 1);

/// `region_of_face`'s border flags, counts and cut (what PartitionFaces fills
/// after the partition).
void CountRegionBorders(const std::vector<std::array<int, 3>>& neighbours,
                        FacePartition& partition);

}  // namespace texlume::mesh
