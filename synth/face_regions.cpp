#include "synth/face_regions.h"

#include <algorithm>

namespace texlume::synth {

mesh::FacePartition RegionsForRanks(const std::vector<std::array<int, 3>>& neighbours,
                                    int num_regions, std::uint32_t seed) {
  return mesh::PartitionFaces(neighbours, num_regions, {}, seed);
}

std::vector<int> OrderWithin(const std::vector<int>& order, const std::vector<char>& member,
                             const std::vector<std::array<int, 3>>& neighbours) {
  std::vector<char> visited(member.size(), 0);
  std::vector<int> within;
  for (const int start : order) {
    const auto s = static_cast<std::size_t>(start);
    if (!member[s] || visited[s]) continue;
    std::size_t head = within.size();
    visited[s] = 1;
    within.push_back(start);
    while (head < within.size()) {
      for (const int g : neighbours[static_cast<std::size_t>(within[head])]) {
        if (g < 0 || !member[static_cast<std::size_t>(g)] || visited[static_cast<std::size_t>(g)])
          continue;
        visited[static_cast<std::size_t>(g)] = 1;
        within.push_back(g);
      }
      ++head;
    }
  }
  return within;
}

}  // namespace texlume::synth
