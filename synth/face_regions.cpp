#include "synth/face_regions.h"

#include <algorithm>

namespace texlume::synth {

mesh::FacePartition RegionsForRanks(const std::vector<std::array<int, 3>>& neighbours,
                                    const sfm::VisibilityResult& visibility, int num_regions,
                                    int max_views, std::uint32_t seed) {
  std::vector<std::int32_t> weights(neighbours.size(), 1);
  for (std::size_t f = 0; f < neighbours.size() && f < visibility.triangles.size(); ++f) {
    int views = 0;
    for (const sfm::TriangleView& view : visibility.triangles[f].views)
      views += view.fully_visible ? 1 : 0;
    weights[f] += std::min(views, max_views);
  }
  return mesh::PartitionFaces(neighbours, num_regions, weights, seed);
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
