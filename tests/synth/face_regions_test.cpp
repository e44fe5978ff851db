// Regions of a distributed synthesis and their breadth-first order (issue 33).
#include "synth/face_regions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

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

// From many sources at once: the sources first, then each face one ring further
// from the nearest source than any before it (distances counted here by their
// own search); the piece no source reaches follows from its first start.
TEST(FaceRegions, BreadthFirstFaceOrderFromMovesAFrontAwayFromEverySource) {
  const mesh::TriangleMesh plane = datasets::MakeGridPlane(12, 1.0);
  const std::vector<std::array<int, 3>> neighbours = mesh::FaceNeighbours(plane);
  const std::size_t n = neighbours.size();
  std::vector<char> member(n, 1);
  std::vector<int> sources, starts(n);
  std::iota(starts.begin(), starts.end(), 0);
  for (std::size_t f = 0; f < n; ++f) {
    const double x = (plane.Corner(f, 0) + plane.Corner(f, 1) + plane.Corner(f, 2)).x() / 3.0;
    const int column = static_cast<int>(std::floor((x + 0.5) * 12));
    if (column == 8) member[f] = 0;  // a column of non-members: two pieces
    if (column == 0 || column == 5) sources.push_back(static_cast<int>(f));
  }
  std::reverse(sources.begin(), sources.end());
  // Ring of each member face from the nearest source, by a search of its own.
  std::vector<int> ring(n, -1);
  std::vector<int> queue;
  for (const int f : sources) ring[static_cast<std::size_t>(f)] = 0, queue.push_back(f);
  for (std::size_t head = 0; head < queue.size(); ++head)
    for (const int g : neighbours[static_cast<std::size_t>(queue[head])])
      if (g >= 0 && member[static_cast<std::size_t>(g)] && ring[static_cast<std::size_t>(g)] < 0) {
        ring[static_cast<std::size_t>(g)] = ring[static_cast<std::size_t>(queue[head])] + 1;
        queue.push_back(g);
      }

  const std::vector<int> order =
      mesh::BreadthFirstFaceOrderFrom(sources, starts, member, neighbours);
  ASSERT_EQ(order.size(), static_cast<std::size_t>(std::count(member.begin(), member.end(), 1)));
  ASSERT_TRUE(std::equal(sources.begin(), sources.end(), order.begin()));
  std::size_t reached = 0;
  while (reached < order.size() && ring[static_cast<std::size_t>(order[reached])] >= 0) {
    if (reached > 0) {
      EXPECT_GE(ring[static_cast<std::size_t>(order[reached])],
                ring[static_cast<std::size_t>(order[reached - 1])]);
    }
    ++reached;
  }
  ASSERT_GT(reached, sources.size());
  ASSERT_LT(reached, order.size());  // the piece right of the column follows
  // The rest: the right piece, from its lowest face (starts ascend), each face
  // after it next to one before it.
  std::vector<char> before(n, 0);
  for (std::size_t k = reached; k < order.size(); ++k) {
    const auto f = static_cast<std::size_t>(order[k]);
    EXPECT_LT(ring[f], 0);
    bool next_to_earlier = false;
    for (const int g : neighbours[f])
      next_to_earlier |= g >= 0 && before[static_cast<std::size_t>(g)];
    EXPECT_EQ(next_to_earlier, k > reached) << k;
    before[f] = 1;
  }
  int lowest_unreached = -1;
  for (std::size_t f = 0; f < n && lowest_unreached < 0; ++f)
    if (member[f] && ring[f] < 0) lowest_unreached = static_cast<int>(f);
  EXPECT_EQ(order[reached], lowest_unreached);
  // Every member once, and nothing else.
  std::vector<int> sorted = order, members;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t f = 0; f < n; ++f)
    if (member[f]) members.push_back(static_cast<int>(f));
  EXPECT_EQ(sorted, members);
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

// The band rank 0 places first: every border face and every face with an edge
// neighbour on a border, nothing else (a grid cut into 3 regions).
TEST(FaceRegions, TheBandPlacedFirstHoldsTheBordersAndTheFacesNextToThem) {
  const std::vector<std::array<int, 3>> neighbours =
      mesh::FaceNeighbours(datasets::MakeGridPlane(30, 1.0));
  const mesh::FacePartition p = RegionsForRanks(neighbours, 3, 1);
  const std::vector<char> band = BordersPlacedFirst(p, neighbours);
  ASSERT_EQ(band.size(), neighbours.size());
  std::size_t borders = 0, next_to = 0;
  for (std::size_t f = 0; f < band.size(); ++f) {
    bool touches_border = false, touches_other_region = false;
    for (const int g : neighbours[f]) {
      if (g < 0) continue;
      touches_border |= p.on_border[static_cast<std::size_t>(g)] != 0;
      touches_other_region |= p.region_of_face[static_cast<std::size_t>(g)] != p.region_of_face[f];
    }
    EXPECT_EQ(p.on_border[f] != 0, touches_other_region) << f;
    EXPECT_EQ(band[f] != 0, p.on_border[f] || touches_border) << f;
    borders += p.on_border[f] ? 1 : 0;
    next_to += band[f] && !p.on_border[f] ? 1 : 0;
  }
  // A band a few faces wide along the cuts: more than the borders, far from everything.
  EXPECT_GT(borders, 0u);
  EXPECT_GT(next_to, borders / 2);
  EXPECT_LT(borders + next_to, neighbours.size() / 2);
}

}  // namespace
}  // namespace texlume::synth
