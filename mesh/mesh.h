#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace texlume::mesh {

/// An indexed triangle mesh in the world frame (the COLMAP model's frame).
/// Faces are counter-clockwise seen from the side their normal points to:
/// normal = (v1 - v0) x (v2 - v0). The order v0, v1, v2 is kept from the file,
/// because the triangle frame of paper 003 §3.0.2 takes its X axis along v0->v1.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> faces;

  std::size_t NumFaces() const { return faces.size(); }
  std::size_t NumVertices() const { return vertices.size(); }
  /// Corner `k` (0..2) of face `f`.
  const Eigen::Vector3d& Corner(std::size_t f, int k) const {
    return vertices[static_cast<std::size_t>(faces[f][static_cast<std::size_t>(k)])];
  }
};

/// How LoadMesh / CleanMesh repair a mesh. Every repair is counted in MeshReport.
struct MeshCleanOptions {
  /// Vertices closer than this, relative to the bounding-box diagonal, are merged
  /// into one (duplicate vertices). Range [0, 1e-2]; 0 merges exact copies only.
  double weld_relative_tolerance = 1e-9;
  /// Faces with area below this times the squared bounding-box diagonal are
  /// degenerate and removed (as are faces with a repeated vertex). Range [0, 1e-3].
  double degenerate_relative_area = 1e-14;
  /// Flip faces so that each connected component is consistently oriented, and
  /// closed components face outwards (positive signed volume).
  bool fix_orientation = true;

  /// Throws OptionError when a value is out of range.
  void Check() const;
};

/// What was wrong with a mesh and what was done about it.
struct MeshReport {
  std::size_t input_vertices = 0;
  std::size_t input_faces = 0;            ///< polygons as read
  std::size_t polygons_triangulated = 0;  ///< faces with more than 3 corners, fanned
  std::size_t duplicate_vertices_merged = 0;
  std::size_t degenerate_faces_removed = 0;  ///< repeated corner or (near) zero area
  std::size_t duplicate_faces_removed = 0;   ///< same three vertices as an earlier face
  std::size_t unused_vertices_removed = 0;
  /// Edges shared by more than two faces. They are kept; adjacency treats them as
  /// boundaries (no neighbour across them).
  std::size_t non_manifold_edges = 0;
  /// Manifold edges whose two faces traverse them in the same direction, as read.
  std::size_t inconsistently_oriented_edges = 0;
  std::size_t faces_flipped = 0;              ///< by the orientation repair
  std::size_t non_orientable_components = 0;  ///< components no flipping can make consistent

  /// One line per problem found, empty for a clean mesh.
  std::vector<std::string> Problems() const;
};

/// A mesh as loaded, with its repair report and, per face, the index of the input
/// polygon it came from.
struct LoadedMesh {
  TriangleMesh mesh;
  MeshReport report;
  std::vector<std::size_t> source_face;
};

/// Reads PLY, OBJ, OFF or STL (by extension) with texlume's own bounded readers
/// (mesh_readers.h), then CleanMesh.
/// Throws InputError naming the file when it is missing, unparsable, or has no
/// faces left after cleaning.
LoadedMesh LoadMesh(const std::filesystem::path& path, const MeshCleanOptions& options = {});

/// Repairs a polygon soup (vertex positions, faces as vertex index lists) into a
/// TriangleMesh; see MeshCleanOptions. `label` names the source in errors.
/// Throws InputError for out-of-range indices, non-finite positions or no faces.
LoadedMesh CleanMesh(const std::vector<Eigen::Vector3d>& vertices,
                     const std::vector<std::vector<int>>& polygons, const MeshCleanOptions& options,
                     const std::string& label);

/// Writes the mesh (PLY, OBJ, OFF or STL by extension) through OpenMesh, atomically.
void SaveMesh(const TriangleMesh& mesh, const std::filesystem::path& path);

/// Unit face normals (v1 - v0) x (v2 - v0), normalised; zero for zero-area faces.
std::vector<Eigen::Vector3d> FaceNormals(const TriangleMesh& mesh);
/// Face areas in squared world units.
std::vector<double> FaceAreas(const TriangleMesh& mesh);

/// For each face, the face across its edges (v0,v1), (v1,v2), (v2,v0), or -1 at a
/// boundary or a non-manifold edge.
std::vector<std::array<int, 3>> FaceNeighbours(const TriangleMesh& mesh);

/// Breadth-first order of all faces over edge adjacency, starting at `seed_face`
/// (paper 003 §3.0.2: every face but the first has a processed neighbour).
/// Other connected components follow, each from its lowest-index face.
/// Throws std::out_of_range for an invalid seed.
std::vector<int> BreadthFirstFaceOrder(const TriangleMesh& mesh,
                                       const std::vector<std::array<int, 3>>& neighbours,
                                       int seed_face);

/// The faces with `member[f]`, breadth first over edge adjacency within them:
/// each connected piece starts at its first face in `starts`, and the pieces
/// follow in that order (so a piece's faces, but the first, each have a
/// neighbour before them). Faces of no piece start in `starts` are left out.
std::vector<int> BreadthFirstFaceOrderWithin(const std::vector<int>& starts,
                                             const std::vector<char>& member,
                                             const std::vector<std::array<int, 3>>& neighbours);

/// The faces with `member[f]`, breadth first over edge adjacency within them
/// from every face of `sources` at once: the sources first (in their order,
/// those that are members), then their members' neighbours ring by ring, so
/// that a front moves away from all of them together. The faces no source
/// reaches follow as BreadthFirstFaceOrderWithin(starts, ...) orders them.
std::vector<int> BreadthFirstFaceOrderFrom(const std::vector<int>& sources,
                                           const std::vector<int>& starts,
                                           const std::vector<char>& member,
                                           const std::vector<std::array<int, 3>>& neighbours);

/// Summary figures of a mesh.
struct MeshStats {
  std::size_t vertices = 0;
  std::size_t faces = 0;
  std::size_t edges = 0;
  std::size_t boundary_edges = 0;
  std::size_t components = 0;
  double surface_area = 0.0;      ///< squared world units
  double mean_edge_length = 0.0;  ///< world units
  Eigen::Vector3d bbox_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max = Eigen::Vector3d::Zero();
};
MeshStats ComputeMeshStats(const TriangleMesh& mesh);

/// The centre of the vertices' bounding box; the origin for a mesh without vertices.
Eigen::Vector3d BoundingBoxCentre(const TriangleMesh& mesh);

/// Smooth (area-weighted) vertex normals.
std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh);

/// The smooth normal at barycentric (b0, b1, b2) of face f: its vertex normals
/// (VertexNormals) interpolated and normalised, as the renderer and the viewer shade.
Eigen::Vector3d SmoothNormalAt(const TriangleMesh& mesh,
                               const std::vector<Eigen::Vector3d>& vertex_normals, std::size_t f,
                               const Eigen::Vector3d& barycentric);

/// 1-to-4 midpoint subdivision (shared edge midpoints welded).
TriangleMesh SubdivideMidpoint(const TriangleMesh& mesh);

}  // namespace texlume::mesh
