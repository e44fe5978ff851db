// Regions of a distributed synthesis and their breadth-first order (issue 33).
#include "synth/face_regions.h"

#include <gtest/gtest.h>

#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"

namespace texlume::synth {
namespace {

TEST(FaceRegions, OrderWithinVisitsARegionBreadthFirst) {
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(3, 1.0);
  const std::vector<std::array<int, 3>> neighbours = mesh::FaceNeighbours(sphere);
  const mesh::FacePartition p = mesh::PartitionFaces(neighbours, 3);
  const std::vector<int> order = mesh::BreadthFirstFaceOrder(sphere, neighbours, 17);
  for (int region = 0; region < 3; ++region) {
    std::vector<char> member(neighbours.size(), 0);
    std::size_t members = 0;
    for (std::size_t f = 0; f < member.size(); ++f)
      if (p.region_of_face[f] == region && !p.on_border[f]) member[f] = 1, ++members;
    const std::vector<int> within = OrderWithin(order, member, neighbours);
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

TEST(FaceRegions, RegionsForRanksWeighFacesByTheirViews) {
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(30, 1.0);
  const std::vector<std::array<int, 3>> neighbours = mesh::FaceNeighbours(plane);
  sfm::VisibilityResult visibility;
  visibility.triangles.resize(neighbours.size());
  // Faces of the left half are fully seen in 6 photos (weight 1 + min(6, 4) = 5), the
  // others in none (weight 1): the right half's region holds more faces.
  for (std::size_t f = 0; f < neighbours.size(); ++f)
    if (plane.vertices[static_cast<std::size_t>(plane.faces[f][0])].x() < 0.0)
      for (int v = 0; v < 6; ++v) {
        sfm::TriangleView view;
        view.fully_visible = true;
        visibility.triangles[f].views.push_back(view);
      }
  const mesh::FacePartition p = RegionsForRanks(neighbours, visibility, 2, 4, 1);
  const std::size_t larger = std::max(p.faces_in_region[0], p.faces_in_region[1]);
  const std::size_t smaller = std::min(p.faces_in_region[0], p.faces_in_region[1]);
  EXPECT_GT(larger, 2 * smaller);
}

}  // namespace
}  // namespace texlume::synth
