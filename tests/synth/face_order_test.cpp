#include "synth/face_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "datasets_synthetic/shapes.h"
#include "mesh/mesh.h"

namespace texlume::synth {
namespace {

// Two icospheres of 1280 faces (two components); a face's key photo is the octant of
// its centroid around its sphere's centre (8 regions a sphere, all connected), and -1
// on a cap of the first sphere.
struct KeyedMesh {
  mesh::TriangleMesh mesh;
  std::vector<std::array<int, 3>> neighbours;
  std::vector<int> key_photo;
};

KeyedMesh TwoSpheresKeyedByOctant() {
  KeyedMesh k;
  mesh::TriangleMesh second = datasets::MakeIcosphere(3, 1.0);
  for (Eigen::Vector3d& v : second.vertices) v.x() += 5.0;
  k.mesh = datasets::JoinMeshes(datasets::MakeIcosphere(3, 1.0), second);
  k.neighbours = mesh::FaceNeighbours(k.mesh);
  for (std::size_t f = 0; f < k.mesh.faces.size(); ++f) {
    Eigen::Vector3d c = (k.mesh.Corner(f, 0) + k.mesh.Corner(f, 1) + k.mesh.Corner(f, 2)) / 3.0;
    if (c.x() > 2.5) c.x() -= 5.0;
    k.key_photo.push_back(
        c.z() > 0.9 && f < 1280 ? -1 : (c.x() > 0) + 2 * (c.y() > 0) + 4 * (c.z() > 0));
  }
  return k;
}

// Connected regions of faces sharing a key photo.
int KeyRegions(const KeyedMesh& k) {
  std::vector<char> seen(k.key_photo.size(), 0);
  int regions = 0;
  for (std::size_t s = 0; s < seen.size(); ++s) {
    if (seen[s]) continue;
    ++regions;
    std::vector<std::size_t> stack{s};
    seen[s] = 1;
    while (!stack.empty()) {
      const std::size_t f = stack.back();
      stack.pop_back();
      for (const int g : k.neighbours[f])
        if (g >= 0 && !seen[static_cast<std::size_t>(g)] &&
            k.key_photo[static_cast<std::size_t>(g)] == k.key_photo[f]) {
          seen[static_cast<std::size_t>(g)] = 1;
          stack.push_back(static_cast<std::size_t>(g));
        }
    }
  }
  return regions;
}

int PhotoSwitches(const std::vector<int>& order, const std::vector<int>& key_photo) {
  int switches = 0;
  for (std::size_t i = 1; i < order.size(); ++i)
    switches += key_photo[static_cast<std::size_t>(order[i])] !=
                key_photo[static_cast<std::size_t>(order[i - 1])];
  return switches;
}

TEST(PhotoByPhotoBreadthFirstOrder, GrowsFromPlacedNeighboursAndVisitsEachRegionOnce) {
  const KeyedMesh k = TwoSpheresKeyedByOctant();
  const int seed = 700;
  const std::vector<int> order = PhotoByPhotoBreadthFirstOrder(k.neighbours, k.key_photo, seed);
  ASSERT_EQ(order.size(), k.mesh.faces.size());
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], static_cast<int>(i));
  EXPECT_EQ(order.front(), seed);
  // Every face but the first of each component has a neighbour placed before it.
  std::vector<char> placed(order.size(), 0);
  int starts = 0;
  for (const int f : order) {
    bool after_neighbour = false;
    for (const int g : k.neighbours[static_cast<std::size_t>(f)])
      after_neighbour = after_neighbour || (g >= 0 && placed[static_cast<std::size_t>(g)]);
    starts += !after_neighbour;
    placed[static_cast<std::size_t>(f)] = 1;
  }
  EXPECT_EQ(starts, 2);
  // Each connected region of one key photo is placed in one run: 17 regions (8 octants
  // a sphere and the cap), so at most 16 changes of photo.
  const int regions = KeyRegions(k);
  EXPECT_EQ(regions, 17);
  EXPECT_LE(PhotoSwitches(order, k.key_photo), regions - 1);
  // Plain breadth first changes photo far more often.
  EXPECT_GT(PhotoSwitches(mesh::BreadthFirstFaceOrder(k.mesh, k.neighbours, seed), k.key_photo),
            10 * regions);
}

TEST(FacesByPhoto, GroupsFacesByKeyPhotoInIndexOrderAndKeepsIndexOrderWhenPhotosFit) {
  const std::vector<int> key_photo = {2, -1, 0, 2, 0, 1, -1};
  EXPECT_EQ(FacesByPhoto(key_photo, true), (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(FacesByPhoto(key_photo, false), (std::vector<std::size_t>{2, 4, 5, 0, 3, 1, 6}));
}

TEST(PhotosHeldTogether, OnlyACacheTooSmallForEveryPhotoSplitsThem) {
  std::vector<MeshPhoto> photos(2);
  photos[0].pixels = PhotoPixels(cv::Mat(2, 2, CV_32FC3));
  photos[1].pixels = PhotoPixels(cv::Mat(2, 2, CV_32FC3));
  EXPECT_TRUE(PhotosHeldTogether(photos));
  for (const std::uint64_t budget :
       {2 * DecodedPhotoBytes({4, 4}, 3), DecodedPhotoBytes({4, 4}, 3)}) {
    auto cache = std::make_shared<PhotoCache>(budget);
    photos[0].pixels = PhotoPixels(cache, cache->Add("a.png", {4, 4}, 3));
    photos[1].pixels = PhotoPixels(cache, cache->Add("b.png", {4, 4}, 3));
    EXPECT_EQ(PhotosHeldTogether(photos), budget == 2 * DecodedPhotoBytes({4, 4}, 3));
  }
}

// Rectifying from the region the maps reach gives the values of remapping the whole
// photo: maps inside, across and beyond the photo's borders, at sub-pixel positions
// that OpenCV rounds up to the next pixel, and behind the camera (RectificationMaps'
// -1e6).
TEST(RemapPhotoRegion, GivesTheValuesOfRemappingTheWholePhoto) {
  cv::Mat photo(48, 64, CV_32FC3);
  cv::randu(photo, 0.0f, 1.0f);
  std::mt19937 rng(3);
  struct Maps {
    float x0, y0, spread;
  };
  for (const Maps m : {Maps{20.0f, 15.0f, 6.0f}, Maps{-3.0f, 40.0f, 8.0f}, Maps{58.0f, -2.0f, 9.0f},
                       Maps{62.99f, 46.99f, 0.02f}, Maps{30.0f, 20.0f, 100.0f}}) {
    cv::Mat map_x(9, 11, CV_32FC1), map_y(9, 11, CV_32FC1);
    std::uniform_real_distribution<float> d(0.0f, m.spread);
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 11; ++i) {
        map_x.at<float>(j, i) = m.x0 + d(rng);
        map_y.at<float>(j, i) = m.y0 + d(rng);
      }
    map_x.at<float>(0, 0) = map_y.at<float>(0, 0) = -1e6f;
    cv::Mat whole, region;
    cv::remap(photo, whole, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
    // A photo as the cache stores it: 8-bit, read back through its region.
    RemapPhotoRegion(PhotoPixels(photo), map_x, map_y, region);
    EXPECT_EQ(cv::norm(whole, region, cv::NORM_INF), 0.0) << m.x0 << ", " << m.y0;
  }
  cv::Mat photo8;
  photo.convertTo(photo8, CV_8UC3, 255.0);
  cv::Mat map_x(5, 5, CV_32FC1, cv::Scalar(10.4f)), map_y(5, 5, CV_32FC1, cv::Scalar(7.6f));
  cv::Mat whole, region;
  cv::remap(PhotoDisplayRgb(photo8), whole, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  RemapPhotoRegion(PhotoPixels(photo8), map_x, map_y, region);
  EXPECT_EQ(cv::norm(whole, region, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace texlume::synth
