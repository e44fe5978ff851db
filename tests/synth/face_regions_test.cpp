// Regions of a distributed synthesis and their breadth-first order (issue 33).
#include "synth/face_regions.h"

#include <gtest/gtest.h>

#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"

namespace texlume::synth {
namespace {

TEST(FaceRegions, BreadthFirstFaceOrderWithinVisitsARegionBreadthFirst) {
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(3, 1.0);
  const std::vector<std::array<int, 3>> neighbours = mesh::FaceNeighbours(sphere);
  const mesh::FacePartition p = mesh::PartitionFaces(neighbours, 3);
  const std::vector<int> order = mesh::BreadthFirstFaceOrder(sphere, neighbours, 17);
  for (int region = 0; region < 3; ++region) {
    std::vector<char> member(neighbours.size(), 0);
    std::size_t members = 0;
    for (std::size_t f = 0; f < member.size(); ++f)
      if (p.region_of_face[f] == region && !p.on_border[f]) member[f] = 1, ++members;
    const std::vector<int> within = mesh::BreadthFirstFaceOrderWithin(order, member, neighbours);
    ASSERT_EQ(within.size(), members);
    // Each face after a piece's first has a member neighbour before it; pieces
    // start in `order`'s order.
    std::vector<char> placed(member.size(), 0);
    std::size_t last_start = 0, starts = 0;
    for (const int f : within) {
      ASSERT_TRUE(member[static_cast<std::size_t>(f)]);
      ASSERT_FALSE(placed[static_cast<std::size_t>(f)]);
      bool has_placed_neighbour = false;
      for (const int g : neighbours[static_cast<std::size_t>(f)])
        has_placed_neighbour =
            has_placed_neighbour || (g >= 0 && placed[static_cast<std::size_t>(g)]);
      if (!has_placed_neighbour) {
        const auto at =
            static_cast<std::size_t>(std::find(order.begin(), order.end(), f) - order.begin());
        EXPECT_GE(at, last_start);
        last_start = at, ++starts;
      }
      placed[static_cast<std::size_t>(f)] = 1;
    }
    EXPECT_LE(starts, 3u) << region;  // METIS's regions are (nearly) in one piece
  }
}

TEST(FaceRegions, RegionsForRanksHoldEqualFaceCounts) {
  const std::vector<std::array<int, 3>> neighbours =
      mesh::FaceNeighbours(datasets::MakeGridPlane(30, 1.0));
  const mesh::FacePartition p = RegionsForRanks(neighbours, 3, 1);
  for (const std::size_t faces : p.faces_in_region)
    EXPECT_NEAR(static_cast<double>(faces), neighbours.size() / 3.0,
                0.05 * neighbours.size() / 3.0);
  EXPECT_EQ(p.region_of_face, RegionsForRanks(neighbours, 3, 1).region_of_face);
}

}  // namespace
}  // namespace texlume::synth
