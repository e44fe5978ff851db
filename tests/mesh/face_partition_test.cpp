// The faces' partition into regions, one per rank of a distributed synthesis (issue 33).
#include "mesh/face_partition.h"

#include <gtest/gtest.h>

#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"

namespace texlume::mesh {
namespace {

// Regions that cover every face, of about equal size, whose border flags and
// cut are those of the regions (counted here by brute force).
void ExpectPartitionOf(const std::vector<std::array<int, 3>>& neighbours, const FacePartition& p,
                       int regions) {
  ASSERT_EQ(p.region_of_face.size(), neighbours.size());
  std::vector<std::size_t> sizes(static_cast<std::size_t>(regions), 0);
  std::size_t cut_half_edges = 0;
  for (std::size_t f = 0; f < neighbours.size(); ++f) {
    const int r = p.region_of_face[f];
    ASSERT_GE(r, 0);
    ASSERT_LT(r, regions);
    ++sizes[static_cast<std::size_t>(r)];
    bool border = false;
    for (const int g : neighbours[f])
      if (g >= 0 && p.region_of_face[static_cast<std::size_t>(g)] != r)
        border = true, ++cut_half_edges;
    EXPECT_EQ(p.on_border[f] != 0, border) << f;
  }
  EXPECT_EQ(p.cut_edges, cut_half_edges / 2);
  EXPECT_EQ(p.faces_in_region, sizes);
  const double mean = static_cast<double>(neighbours.size()) / regions;
  for (const std::size_t size : sizes) EXPECT_NEAR(static_cast<double>(size), mean, 0.1 * mean);
}

TEST(FacePartition, RegionsOfAboutEqualSizeWithFewCutEdges) {
  const TriangleMesh sphere = datasets::MakeIcosphere(4, 1.0);  // 5120 faces
  const std::vector<std::array<int, 3>> neighbours = FaceNeighbours(sphere);
  for (const int regions : {2, 3, 8}) {
    const FacePartition p = PartitionFaces(neighbours, regions);
    ExpectPartitionOf(neighbours, p, regions);
    // Compact regions: a region of n faces on a sphere has a border of about
    // sqrt(n) edges, far fewer than a random split's (about 2/3 of all edges).
    EXPECT_LT(p.cut_edges, 12u * static_cast<std::size_t>(std::sqrt(5120.0 * regions))) << regions;
  }
}

TEST(FacePartition, DeterministicForASeedAndWeighted) {
  const TriangleMesh plane = datasets::MakeGridPlane(40, 1.0);
  const std::vector<std::array<int, 3>> neighbours = FaceNeighbours(plane);
  EXPECT_EQ(PartitionFaces(neighbours, 3, {}, 7).region_of_face,
            PartitionFaces(neighbours, 3, {}, 7).region_of_face);
  // Faces of the left half weigh 3: the left half's regions hold fewer faces.
  std::vector<std::int32_t> weights(plane.faces.size(), 1);
  for (std::size_t f = 0; f < plane.faces.size(); ++f)
    if (plane.vertices[static_cast<std::size_t>(plane.faces[f][0])].x() < 0.0) weights[f] = 3;
  const FacePartition p = PartitionFaces(neighbours, 2, weights);
  std::array<double, 2> weight_of{};
  for (std::size_t f = 0; f < plane.faces.size(); ++f)
    weight_of[static_cast<std::size_t>(p.region_of_face[f])] += weights[f];
  EXPECT_NEAR(weight_of[0], weight_of[1], 0.1 * weight_of[0]);
  EXPECT_NE(p.faces_in_region[0], p.faces_in_region[1]);
}

TEST(FacePartition, OneRegionHasNoBorderAndBadArgumentsAreRefused) {
  const std::vector<std::array<int, 3>> neighbours =
      FaceNeighbours(datasets::MakeIcosphere(1, 1.0));
  const FacePartition one = PartitionFaces(neighbours, 1);
  EXPECT_EQ(one.cut_edges, 0u);
  EXPECT_EQ(one.faces_in_region, std::vector<std::size_t>{neighbours.size()});
  for (const char b : one.on_border) EXPECT_EQ(b, 0);
  EXPECT_THROW(PartitionFaces(neighbours, 0), std::invalid_argument);
  EXPECT_THROW(PartitionFaces(neighbours, 2, {1, 2}), std::invalid_argument);
  EXPECT_THROW(PartitionFaces(neighbours, 2, std::vector<std::int32_t>(neighbours.size(), 0)),
               std::invalid_argument);
}

}  // namespace
}  // namespace texlume::mesh
