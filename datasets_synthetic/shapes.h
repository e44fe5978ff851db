#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "mesh/mesh.h"

namespace texlume::datasets {

/// Shapes of the synthetic objects (world frame: Z up, object centred at the origin).
enum class SceneShape {
  kSphere,    ///< sphere of radius 1
  kCylinder,  ///< capped column of radius 0.6 and height 1.6
  kPlane,     ///< 2 x 2 square in the z = 0 plane, facing +Z
  kTorus,     ///< torus of radii 0.8 and 0.35 around Z (the less regular shape)
};
std::string_view SceneShapeName(SceneShape shape);  ///< "sphere", "cylinder", "plane", "torus"
std::optional<SceneShape> SceneShapeFromName(std::string_view name);

/// A point of the undisplaced (base) surface with its derivatives with respect to
/// the material coordinates (u, v), which are world units along the surface.
struct SurfacePoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit, outwards; = d_du x d_dv normalised
  Eigen::Vector3d d_du = Eigen::Vector3d::UnitX();    ///< dS/du
  Eigen::Vector3d d_dv = Eigen::Vector3d::UnitY();    ///< dS/dv
};

/// One parametric piece of a shape's base surface and its material domain.
struct SurfacePatch {
  enum class Domain { kRectangle, kDisk };
  Domain domain = Domain::kRectangle;
  double u0 = 0, u1 = 1, v0 = 0, v1 = 1;  ///< material-coordinate bounds (world units)
  bool periodic_u = false;                ///< u wraps: period u1 - u0
  bool periodic_v = false;                ///< v wraps: period v1 - v0
  /// kDisk: the patch is the disk inscribed in the rectangle.
  std::function<SurfacePoint(double u, double v)> eval;
};

/// The base surface of a shape as patches (a cylinder: side and two caps).
std::vector<SurfacePatch> ShapePatches(SceneShape shape);

/// The coarse, undisplaced, low-poly mesh of a shape (what a mesher would give).
mesh::TriangleMesh CoarseMesh(SceneShape shape);

/// The coarse mesh of a shape with about `target_faces` triangles (a monument-scale
/// scene: issue 33), as regular as the shape allows: the cylinder, plane and torus
/// as grids whose cells are about square (the column's caps as rings: MakeColumn),
/// within 10 % of the target from about 2000 faces up, the sphere as the icosphere whose 20 * 4^N
/// faces are nearest the target on a log scale (within a factor of 2). `target_faces` >= 1.
mesh::TriangleMesh ShapeMeshWithFaces(SceneShape shape, std::int64_t target_faces);

/// Mesh generators (outward normals), also used by tests.
mesh::TriangleMesh MakeIcosphere(int subdivisions, double radius);
mesh::TriangleMesh MakeCylinder(int segments_around, int segments_along, double radius,
                                double height);
/// A column as a monument's mesher would give it: the side as MakeCylinder's,
/// each cap as concentric rings of about square cells (no long fan triangles).
mesh::TriangleMesh MakeColumn(int around, int along, double radius, double height);
mesh::TriangleMesh MakeGridPlane(int segments, double size);
mesh::TriangleMesh MakeTorus(int segments_around, int segments_tube, double major_radius,
                             double minor_radius);
/// Two grid planes (z = 0 and y = 0) crossing along the x axis (`segments` even):
/// every edge on the line is shared by four faces, a non-manifold mesh. Throws
/// std::invalid_argument when `segments` is odd (no line of vertices on the axis).
mesh::TriangleMesh MakeCrossedPlanes(int segments, double size);
/// Both meshes in one (b's vertices after a's): a mesh of two components.
mesh::TriangleMesh JoinMeshes(const mesh::TriangleMesh& a, const mesh::TriangleMesh& b);
/// An irregular, scan-like closed mesh (20 * 4^subdivisions faces, seeded): an
/// icosphere whose vertices are moved along the sphere by up to a third of an
/// edge (triangles of uneven size and shape, as a mesher of a scan gives), then
/// pushed out or in by `relief` (a share of the radius) with 8 random smooth
/// bumps, a lumpy stone rather than a sphere (0: on the sphere).
mesh::TriangleMesh MakeScanLikeMesh(int subdivisions, double radius, double relief, unsigned seed);

}  // namespace texlume::datasets
