#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "sfm/visibility.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {

// Face orders that keep the photo cache warm (issue 33, "photos on demand"): when
// the photos do not all fit in memory at once (core/photo_cache.h), the passes over
// the faces visit them photo by photo, so that each photo is decoded about once per
// region of the mesh it sees best, not once per face.

/// Whether every photo lives in memory at once: held, or decoded through a cache
/// that holds them all. Then every pass keeps its plain order.
bool PhotosHeldTogether(const std::vector<MeshPhoto>& photos);

/// Each face's key photo: the index into `photos` of its best view
/// (sfm::TriangleVisibility::best_view), or -1 when it has none among them.
std::vector<int> KeyPhotoOfFaces(const sfm::VisibilityResult& visibility,
                                 const std::vector<MeshPhoto>& photos);

/// The faces in index order when `held_together`; else grouped by key photo
/// (faces without one last), each group in index order.
std::vector<std::size_t> FacesByPhoto(const std::vector<int>& key_photo, bool held_together);

/// Algorithm 2's breadth-first growth from `seed_face`, photo by photo: a face
/// joins the frontier when a neighbour is placed, as in mesh::BreadthFirstFaceOrder,
/// so every face but the first of each connected component has a neighbour placed
/// before it; but the frontier faces whose key photo is the current one are placed
/// first (oldest first), and only when none is left does the newest frontier face
/// (beside the faces just placed, whose photos the cache still holds) choose the
/// next photo. `neighbours` as mesh::FaceNeighbours gives them.
std::vector<int> PhotoByPhotoBreadthFirstOrder(const std::vector<std::array<int, 3>>& neighbours,
                                               const std::vector<int>& key_photo, int seed_face);

}  // namespace texlume::synth
