#include "synth/face_order.h"

#include <algorithm>
#include <deque>
#include <map>
#include <stdexcept>
#include <string>

namespace texlume::synth {

bool PhotosHeldTogether(const std::vector<MeshPhoto>& photos) {
  for (const MeshPhoto& photo : photos)
    if (photo.pixels.cache() && !photo.pixels.cache()->HoldsAll()) return false;
  return true;
}

std::vector<int> KeyPhotoOfFaces(const sfm::VisibilityResult& visibility,
                                 const std::vector<MeshPhoto>& photos) {
  std::map<sfm::ImageId, int> photo_index;
  for (std::size_t n = 0; n < photos.size(); ++n)
    photo_index[photos[n].image_id] = static_cast<int>(n);
  std::vector<int> key(visibility.triangles.size(), -1);
  for (std::size_t f = 0; f < key.size(); ++f) {
    const sfm::TriangleVisibility& tv = visibility.triangles[f];
    if (tv.best_view_source == sfm::BestViewSource::kNone) continue;
    const auto it = photo_index.find(tv.best_view);
    if (it != photo_index.end()) key[f] = it->second;
  }
  return key;
}

std::vector<std::size_t> FacesByPhoto(const std::vector<int>& key_photo, bool held_together) {
  std::vector<std::size_t> order(key_photo.size());
  for (std::size_t f = 0; f < order.size(); ++f) order[f] = f;
  if (held_together) return order;
  // -1 (no key photo) sorts last as the largest unsigned key.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return static_cast<unsigned>(key_photo[a]) < static_cast<unsigned>(key_photo[b]);
  });
  return order;
}

namespace {

// The frontier of the photo-by-photo growth: every frontier face in one queue by
// age and in one queue per key photo; a face placed through one queue is skipped
// when the other reaches it.
class PhotoFrontier {
 public:
  explicit PhotoFrontier(const std::vector<int>& key_photo)
      : key_photo_(key_photo),
        by_photo_(static_cast<std::size_t>(
            std::max(-1, *std::max_element(key_photo.begin(), key_photo.end())) + 2)),
        discovered_(key_photo.size(), 0),
        placed_(key_photo.size(), 0) {}

  bool Discovered(int f) const { return discovered_[static_cast<std::size_t>(f)] != 0; }

  void Discover(int f) {
    discovered_[static_cast<std::size_t>(f)] = 1;
    by_age_.push_back(f);
    Queue(key_photo_[static_cast<std::size_t>(f)]).push_back(f);
  }

  // The next face to place: the current photo's oldest, else the newest of all
  // (which makes its photo the current one); -1 when the frontier is empty.
  int Next() {
    int f = PopUnplaced(Queue(current_photo_));
    if (f < 0) {
      f = PopNewestUnplaced(by_age_);
      if (f >= 0) current_photo_ = key_photo_[static_cast<std::size_t>(f)];
    }
    if (f >= 0) placed_[static_cast<std::size_t>(f)] = 1;
    return f;
  }

 private:
  std::deque<int>& Queue(int photo) { return by_photo_[static_cast<std::size_t>(photo + 1)]; }
  int PopUnplaced(std::deque<int>& queue) {
    while (!queue.empty() && placed_[static_cast<std::size_t>(queue.front())]) queue.pop_front();
    if (queue.empty()) return -1;
    const int f = queue.front();
    queue.pop_front();
    return f;
  }

  int PopNewestUnplaced(std::deque<int>& queue) {
    while (!queue.empty() && placed_[static_cast<std::size_t>(queue.back())]) queue.pop_back();
    if (queue.empty()) return -1;
    const int f = queue.back();
    queue.pop_back();
    return f;
  }

  const std::vector<int>& key_photo_;
  std::vector<std::deque<int>> by_photo_;  // index key + 1 (0: no key photo)
  std::deque<int> by_age_;
  std::vector<char> discovered_, placed_;
  int current_photo_ = -1;
};

}  // namespace

std::vector<int> PhotoByPhotoBreadthFirstOrder(const std::vector<std::array<int, 3>>& neighbours,
                                               const std::vector<int>& key_photo, int seed_face) {
  const int n = static_cast<int>(neighbours.size());
  if (key_photo.size() != neighbours.size())
    throw std::invalid_argument("a key photo per face is needed");
  if (seed_face < 0 || seed_face >= n)
    throw std::out_of_range("seed face " + std::to_string(seed_face) + " is not a face index");
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(n));
  PhotoFrontier frontier(key_photo);
  frontier.Discover(seed_face);
  int next_start = 0;  // a later component starts at its lowest face index
  while (static_cast<int>(order.size()) < n) {
    int f = frontier.Next();
    if (f < 0) {
      while (frontier.Discovered(next_start)) ++next_start;
      frontier.Discover(next_start);
      f = frontier.Next();
    }
    order.push_back(f);
    for (const int g : neighbours[static_cast<std::size_t>(f)])
      if (g >= 0 && !frontier.Discovered(g)) frontier.Discover(g);
  }
  return order;
}

}  // namespace texlume::synth
