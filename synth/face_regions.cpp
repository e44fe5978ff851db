#include "synth/face_regions.h"

namespace texlume::synth {

mesh::FacePartition RegionsForRanks(const std::vector<std::array<int, 3>>& neighbours,
                                    int num_regions, std::uint32_t seed) {
  return mesh::PartitionFaces(neighbours, num_regions, {}, seed);
}

std::vector<char> BordersPlacedFirst(const mesh::FacePartition& partition,
                                     const std::vector<std::array<int, 3>>& neighbours) {
  std::vector<char> first = partition.on_border;
  for (std::size_t f = 0; f < neighbours.size(); ++f)
    for (const int g : neighbours[f])
      if (g >= 0 && partition.on_border[static_cast<std::size_t>(g)]) first[f] = 1;
  return first;
}

}  // namespace texlume::synth
