#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "mesh/mesh.h"

// The vector field that orients the sample on the surface (paper 004 §III-B):
// a user gives vectors at a few key faces, and radial basis functions
// interpolate them over the mesh (Praun et al. 2000, as the paper does).
//
// The --field file (docs/quilting.md, "The field file"):
//   {"format": "texlume-field", "vectors": [{"face": 12, "direction": [1, 0, 0]}, ...]}
// faces by their 0-based index in the mesh as texlume reads it, directions in
// the mesh's world frame (any length > 0; laid onto the face's plane).

namespace texlume::quilt {

struct KeyVector {
  int face = 0;
  Eigen::Vector3d direction_in_world = Eigen::Vector3d::UnitX();
};

/// Reads a field file. Throws InputError naming it for a malformed file, a face
/// the mesh does not have (`num_faces`), a zero or non-finite direction, a
/// direction along its face's normal, or no vectors at all.
std::vector<KeyVector> ReadFieldFile(const std::filesystem::path& path,
                                     const mesh::TriangleMesh& mesh);

/// Per face, the field direction in the world, in its plane, unit: the key
/// vectors interpolated by Gaussian radial basis functions of the distance
/// between face centroids (width: the mean distance from a key face to its
/// nearest other key, or the mesh's bounding-box diagonal for one key), solved
/// so that each key face gets its own vector exactly, then laid onto each
/// face's plane. A face where the result lies along the normal gets its first
/// edge's direction.
std::vector<Eigen::Vector3d> InterpolateField(const mesh::TriangleMesh& mesh,
                                              const std::vector<KeyVector>& keys);

}  // namespace texlume::quilt
