#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "mesh/mesh.h"

namespace texlume::mesh {

/// Nearest-hit and shadow rays against a triangle mesh (Embree 3), thread safe
/// after construction. Shared by the model renderer and the synthetic-scene
/// renderer.
class RayCaster {
 public:
  /// Throws std::runtime_error when Embree cannot build the scene.
  RayCaster(const std::vector<Eigen::Vector3f>& positions,
            const std::vector<std::array<std::uint32_t, 3>>& triangles, bool high_quality = false);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  struct Hit {
    std::uint32_t triangle = 0;
    double b1 = 0.0, b2 = 0.0;  ///< barycentrics of corners 1 and 2
    double distance = 0.0;      ///< along the (unnormalised) direction, in its units
    Eigen::Vector3d geometric_normal = Eigen::Vector3d::Zero();  ///< Embree's Ng, unnormalised
  };
  /// The nearest triangle along origin + s direction, s in [0, inf).
  std::optional<Hit> Intersect(const Eigen::Vector3d& origin,
                               const Eigen::Vector3d& direction) const;
  /// Whether any triangle lies along origin + s direction, s in [near, inf).
  bool Occluded(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, float near) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A RayCaster over a mesh's faces (its vertices as floats): the model renderer's
/// and the benches' surface.
std::unique_ptr<RayCaster> RayCasterOf(const TriangleMesh& mesh);

}  // namespace texlume::mesh
