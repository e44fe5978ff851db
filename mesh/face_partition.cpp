#include "mesh/face_partition.h"

#include <metis.h>

#include <mutex>
#include <stdexcept>
#include <string>

namespace texlume::mesh {
namespace {

// The dual graph in METIS's compressed rows: a vertex per face, an edge per
// shared mesh edge (both directions).
struct DualGraph {
  std::vector<idx_t> xadj{0}, adjncy;
};

DualGraph DualGraphOf(const std::vector<std::array<int, 3>>& neighbours) {
  DualGraph graph;
  graph.xadj.reserve(neighbours.size() + 1);
  graph.adjncy.reserve(neighbours.size() * 3);
  for (const std::array<int, 3>& across : neighbours) {
    for (const int g : across)
      if (g >= 0) graph.adjncy.push_back(static_cast<idx_t>(g));
    graph.xadj.push_back(static_cast<idx_t>(graph.adjncy.size()));
  }
  return graph;
}

}  // namespace

void CountRegionBorders(const std::vector<std::array<int, 3>>& neighbours,
                        FacePartition& partition) {
  const std::size_t n = neighbours.size();
  partition.on_border.assign(n, 0);
  partition.faces_in_region.assign(static_cast<std::size_t>(partition.num_regions), 0);
  partition.border_faces_in_region.assign(static_cast<std::size_t>(partition.num_regions), 0);
  std::size_t cut_half_edges = 0;
  for (std::size_t f = 0; f < n; ++f) {
    const int region = partition.region_of_face[f];
    for (const int g : neighbours[f]) {
      if (g < 0 || partition.region_of_face[static_cast<std::size_t>(g)] == region) continue;
      partition.on_border[f] = 1;
      ++cut_half_edges;
    }
    ++partition.faces_in_region[static_cast<std::size_t>(region)];
    if (partition.on_border[f])
      ++partition.border_faces_in_region[static_cast<std::size_t>(region)];
  }
  partition.cut_edges = cut_half_edges / 2;
}

FacePartition PartitionFaces(const std::vector<std::array<int, 3>>& neighbours, int num_regions,
                             const std::vector<std::int32_t>& face_weights, std::uint32_t seed) {
  if (num_regions < 1)
    throw std::invalid_argument("regions must be >= 1, not " + std::to_string(num_regions));
  const std::size_t n = neighbours.size();
  if (!face_weights.empty() && face_weights.size() != n)
    throw std::invalid_argument("one weight per face");
  std::vector<idx_t> weights(face_weights.begin(), face_weights.end());
  for (const idx_t w : weights)
    if (w < 1) throw std::invalid_argument("face weights must be >= 1");
  FacePartition partition;
  partition.num_regions = num_regions;
  partition.region_of_face.resize(n);
  if (num_regions == 1 || n < static_cast<std::size_t>(num_regions)) {
    for (std::size_t f = 0; f < n; ++f)
      partition.region_of_face[f] = static_cast<int>(f % static_cast<std::size_t>(num_regions));
  } else {
    DualGraph graph = DualGraphOf(neighbours);
    idx_t vertices = static_cast<idx_t>(n), constraints = 1, parts = num_regions, cut = 0;
    std::array<idx_t, METIS_NOPTIONS> options{};
    METIS_SetDefaultOptions(options.data());
    options[METIS_OPTION_SEED] = static_cast<idx_t>(seed & 0x7fffffff);
    options[METIS_OPTION_NUMBERING] = 0;
    std::vector<idx_t> part(n);
    // METIS keeps global state (its error handling's jump buffers): one call at a time.
    static std::mutex metis_mutex;
    const std::lock_guard<std::mutex> lock(metis_mutex);
    const int status =
        METIS_PartGraphKway(&vertices, &constraints, graph.xadj.data(), graph.adjncy.data(),
                            weights.empty() ? nullptr : weights.data(), nullptr, nullptr, &parts,
                            nullptr, nullptr, options.data(), &cut, part.data());
    if (status != METIS_OK)
      throw std::runtime_error("METIS could not partition " + std::to_string(n) + " faces into " +
                               std::to_string(num_regions) + " regions (status " +
                               std::to_string(status) + ")");
    for (std::size_t f = 0; f < n; ++f) partition.region_of_face[f] = static_cast<int>(part[f]);
  }
  CountRegionBorders(neighbours, partition);
  return partition;
}

}  // namespace texlume::mesh
