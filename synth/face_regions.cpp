#include "synth/face_regions.h"

namespace texlume::synth {

mesh::FacePartition RegionsForRanks(const std::vector<std::array<int, 3>>& neighbours,
                                    int num_regions, std::uint32_t seed) {
  return mesh::PartitionFaces(neighbours, num_regions, {}, seed);
}

}  // namespace texlume::synth
