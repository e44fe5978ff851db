#include "mesh/mesh.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "core/errors.h"
#include "mesh/mesh_readers.h"

namespace texlume::mesh {
namespace {

struct OmTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using OmPolyMesh = OpenMesh::PolyMesh_ArrayKernelT<OmTraits>;

// OpenMesh prints complaints about the files it reads to its own streams; texlume
// reports problems itself, so those streams are silenced once.
void SilenceOpenMesh() {
  static std::once_flag once;
  std::call_once(once, [] {
    omerr().disable();
    omlog().disable();
    omout().disable();
  });
}

std::uint64_t EdgeKey(int a, int b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a, b));
  const auto hi = static_cast<std::uint32_t>(std::max(a, b));
  return (static_cast<std::uint64_t>(lo) << 32) | hi;
}

// For every undirected edge, the faces using it and the corner at which each
// face starts the edge.
struct EdgeUse {
  int face;
  int corner;  // the edge is (corner, corner+1 mod 3) of the face
};
std::unordered_map<std::uint64_t, std::vector<EdgeUse>> EdgeUses(
    const std::vector<std::array<int, 3>>& faces) {
  std::unordered_map<std::uint64_t, std::vector<EdgeUse>> uses;
  uses.reserve(faces.size() * 2);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = faces[f][static_cast<std::size_t>(k)];
      const int b = faces[f][static_cast<std::size_t>((k + 1) % 3)];
      uses[EdgeKey(a, b)].push_back({static_cast<int>(f), k});
    }
  }
  return uses;
}

// True when two faces traverse their shared edge in the same direction.
bool SameDirection(const std::vector<std::array<int, 3>>& faces, const EdgeUse& u,
                   const EdgeUse& w) {
  const auto& fu = faces[static_cast<std::size_t>(u.face)];
  const auto& fw = faces[static_cast<std::size_t>(w.face)];
  return fu[static_cast<std::size_t>(u.corner)] == fw[static_cast<std::size_t>(w.corner)];
}

double SignedVolume(const std::vector<Eigen::Vector3d>& v, const std::array<int, 3>& f) {
  return v[static_cast<std::size_t>(f[0])].dot(
             v[static_cast<std::size_t>(f[1])].cross(v[static_cast<std::size_t>(f[2])])) /
         6.0;
}

}  // namespace

void MeshCleanOptions::Check() const {
  if (!(weld_relative_tolerance >= 0.0 && weld_relative_tolerance <= 1e-2)) {
    throw OptionError("weld_relative_tolerance must be in [0, 1e-2]");
  }
  if (!(degenerate_relative_area >= 0.0 && degenerate_relative_area <= 1e-3)) {
    throw OptionError("degenerate_relative_area must be in [0, 1e-3]");
  }
}

std::vector<std::string> MeshReport::Problems() const {
  std::vector<std::string> out;
  auto add = [&](std::size_t n, const std::string& what) {
    if (n > 0) out.push_back(std::to_string(n) + " " + what);
  };
  add(duplicate_vertices_merged, "duplicate vertices merged");
  add(degenerate_faces_removed, "degenerate faces removed");
  add(duplicate_faces_removed, "duplicate faces removed");
  add(unused_vertices_removed, "unused vertices removed");
  add(non_manifold_edges, "non-manifold edges (kept; treated as boundaries)");
  add(inconsistently_oriented_edges, "inconsistently oriented edges");
  add(faces_flipped, "faces flipped to a consistent outward orientation");
  add(non_orientable_components, "non-orientable components");
  return out;
}

namespace {

// Repairs a polygon soup into a clean triangle mesh (CleanMesh), a method per step;
// the faces, the vertex map and the report being built are its members.
class MeshCleaner {
 public:
  MeshCleaner(const std::vector<Eigen::Vector3d>& vertices,
              const std::vector<std::vector<int>>& polygons, const MeshCleanOptions& options,
              const std::string& label)
      : vertices_(vertices), polygons_(polygons), options_(options), label_(label) {}
  MeshCleaner(const MeshCleaner&) = delete;
  MeshCleaner& operator=(const MeshCleaner&) = delete;

  // Runs the steps in order and returns the cleaned mesh with its report.
  LoadedMesh Run() {
    report_.input_vertices = vertices_.size();
    report_.input_faces = polygons_.size();
    MeasureBounds();
    WeldVertices();
    TriangulatePolygons();
    CountEdgeProblems();
    if (options_.fix_orientation) OrientFaces();
    CompactVertices();
    return std::move(result_);
  }

 private:
  // Checks the coordinates are finite and measures the bounding box and its diagonal.
  void MeasureBounds() {
    lo_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo_;
    for (std::size_t i = 0; i < vertices_.size(); ++i) {
      if (!vertices_[i].allFinite()) {
        throw InputError(label_, "vertex " + std::to_string(i) + " has a non-finite coordinate");
      }
      lo_ = lo_.cwiseMin(vertices_[i]);
      hi = hi.cwiseMax(vertices_[i]);
    }
    diagonal_ = vertices_.empty() ? 0.0 : (hi - lo_).norm();
    if (!std::isfinite(diagonal_)) {
      throw InputError(label_, "the mesh's extent overflows (coordinates near the double's limit)");
    }
  }

  // 1. Weld duplicate vertices on a hash grid (cells of the tolerance size,
  //    neighbouring cells searched so no pair within tolerance is missed).
  void WeldVertices() {
    representative_.resize(vertices_.size());
    const double tol = options_.weld_relative_tolerance * diagonal_;
    const double cell = tol > 0.0 ? tol : 1.0;
    struct KeyHash {
      std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
        return static_cast<std::size_t>(k[0] * 73856093 ^ k[1] * 19349663 ^ k[2] * 83492791);
      }
    };
    std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, KeyHash> grid;
    std::unordered_map<std::array<double, 3>, int, decltype([](const std::array<double, 3>& p) {
                         return std::hash<double>()(p[0]) ^ (std::hash<double>()(p[1]) << 1) ^
                                (std::hash<double>()(p[2]) << 2);
                       })>
        exact;
    for (std::size_t i = 0; i < vertices_.size(); ++i) {
      const Eigen::Vector3d& p = vertices_[i];
      int found = -1;
      if (tol > 0.0) {
        std::array<std::int64_t, 3> key;
        for (int c = 0; c < 3; ++c)
          key[c] = static_cast<std::int64_t>(std::floor((p[c] - lo_[c]) / cell));
        for (int dx = -1; dx <= 1 && found < 0; ++dx)
          for (int dy = -1; dy <= 1 && found < 0; ++dy)
            for (int dz = -1; dz <= 1 && found < 0; ++dz) {
              const auto it = grid.find({key[0] + dx, key[1] + dy, key[2] + dz});
              if (it == grid.end()) continue;
              for (int j : it->second) {
                if ((vertices_[static_cast<std::size_t>(j)] - p).norm() <= tol) {
                  found = j;
                  break;
                }
              }
            }
        if (found < 0) grid[key].push_back(static_cast<int>(i));
      } else {
        const auto [it, inserted] =
            exact.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(i));
        if (!inserted) found = it->second;
      }
      representative_[i] = found < 0 ? static_cast<int>(i) : found;
      if (found >= 0) ++report_.duplicate_vertices_merged;
    }
  }

  // 2. Triangulate (fan), map to representatives, drop degenerate and duplicate faces.
  void TriangulatePolygons() {
    faces_.reserve(polygons_.size());
    min_area_ = options_.degenerate_relative_area * diagonal_ * diagonal_;
    for (std::size_t pi = 0; pi < polygons_.size(); ++pi) {
      const auto& polygon = polygons_[pi];
      if (polygon.size() < 3) {
        ++report_.degenerate_faces_removed;
        continue;
      }
      for (int idx : polygon) {
        if (idx < 0 || static_cast<std::size_t>(idx) >= vertices_.size()) {
          throw InputError(label_, "face " + std::to_string(pi) + " refers to vertex " +
                                       std::to_string(idx) + " but the mesh has " +
                                       std::to_string(vertices_.size()) + " vertices");
        }
      }
      if (polygon.size() > 3) ++report_.polygons_triangulated;
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        AddTriangle({representative_[static_cast<std::size_t>(polygon[0])],
                     representative_[static_cast<std::size_t>(polygon[k])],
                     representative_[static_cast<std::size_t>(polygon[k + 1])]},
                    pi);
      }
    }
    if (faces_.empty()) throw InputError(label_, "the mesh has no usable faces");
  }

  // Keeps triangle `f` of polygon `pi` unless it is degenerate or repeats a kept face.
  void AddTriangle(const std::array<int, 3>& f, std::size_t pi) {
    const Eigen::Vector3d& a = vertices_[static_cast<std::size_t>(f[0])];
    const double area = 0.5 * (vertices_[static_cast<std::size_t>(f[1])] - a)
                                  .cross(vertices_[static_cast<std::size_t>(f[2])] - a)
                                  .norm();
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2] || !(area > min_area_)) {
      ++report_.degenerate_faces_removed;
      return;
    }
    std::array<int, 3> sorted = f;
    std::sort(sorted.begin(), sorted.end());
    if (!seen_.insert(sorted).second) {
      ++report_.duplicate_faces_removed;
      return;
    }
    faces_.push_back(f);
    source_.push_back(pi);
  }

  // 3. Non-manifold edges and orientation: counts the edges used by more than two
  //    faces and those two faces traverse in the same direction.
  void CountEdgeProblems() {
    uses_ = EdgeUses(faces_);
    for (const auto& [key, list] : uses_) {
      if (list.size() > 2) ++report_.non_manifold_edges;
      if (list.size() == 2 && SameDirection(faces_, list[0], list[1])) {
        ++report_.inconsistently_oriented_edges;
      }
    }
  }

  // Orients every connected component consistently, and outwards where it is closed.
  void OrientFaces() {
    // Breadth-first over manifold edges: a face reached through an edge it
    // traverses in the same direction as its parent gets flipped.
    flip_.assign(faces_.size(), -1);  // -1 unvisited, 0 keep, 1 flip
    for (std::size_t seed = 0; seed < faces_.size(); ++seed) {
      if (flip_[seed] >= 0) continue;
      const std::vector<std::size_t> component = PropagateOrientation(seed);
      OrientComponent(component);
    }
  }

  // Decides breadth-first from `seed` which faces of its component flip; returns the
  // component's faces in visiting order.
  std::vector<std::size_t> PropagateOrientation(std::size_t seed) {
    std::vector<std::size_t> component;
    bool orientable = true;
    std::queue<std::size_t> queue;
    flip_[seed] = 0;
    queue.push(seed);
    while (!queue.empty()) {
      const std::size_t f = queue.front();
      queue.pop();
      component.push_back(f);
      for (int k = 0; k < 3; ++k) {
        const int a = faces_[f][static_cast<std::size_t>(k)];
        const int b = faces_[f][static_cast<std::size_t>((k + 1) % 3)];
        const auto& list = uses_[EdgeKey(a, b)];
        if (list.size() != 2) continue;
        const EdgeUse& mine = list[0].face == static_cast<int>(f) ? list[0] : list[1];
        const EdgeUse& other = list[0].face == static_cast<int>(f) ? list[1] : list[0];
        const int relation = SameDirection(faces_, mine, other) ? 1 : 0;  // 1: must differ
        const int wanted = flip_[f] ^ relation;
        const auto g = static_cast<std::size_t>(other.face);
        if (flip_[g] < 0) {
          flip_[g] = wanted;
          queue.push(g);
        } else if (flip_[g] != wanted) {
          orientable = false;
        }
      }
    }
    if (!orientable) ++report_.non_orientable_components;
    return component;
  }

  // Applies the flips to one component, inverting them all where that faces it the
  // right way.
  void OrientComponent(const std::vector<std::size_t>& component) {
    // Closed components face outwards (positive signed volume); open ones keep
    // the orientation of the majority of their faces.
    double volume = 0.0;
    std::size_t flipped = 0;
    bool closed = true;
    for (std::size_t f : component) {
      std::array<int, 3> face = faces_[f];
      if (flip_[f] == 1) std::swap(face[1], face[2]);
      volume += SignedVolume(vertices_, face);
      flipped += static_cast<std::size_t>(flip_[f]);
      for (int k = 0; k < 3 && closed; ++k) {
        closed = uses_[EdgeKey(face[static_cast<std::size_t>(k)],
                               face[static_cast<std::size_t>((k + 1) % 3)])]
                     .size() == 2;
      }
    }
    const bool invert = closed ? volume < 0.0 : 2 * flipped > component.size();
    for (std::size_t f : component) {
      if (invert) flip_[f] ^= 1;
      if (flip_[f] == 1) {
        std::swap(faces_[f][1], faces_[f][2]);
        ++report_.faces_flipped;
      }
    }
  }

  // 4. Compact vertices: keep those used by a face, in their original order.
  void CompactVertices() {
    std::vector<int> new_index(vertices_.size(), -1);
    for (const auto& f : faces_)
      for (int v : f) new_index[static_cast<std::size_t>(v)] = 0;
    int next = 0;
    for (std::size_t i = 0; i < vertices_.size(); ++i) {
      if (new_index[i] == 0) {
        new_index[i] = next++;
        result_.mesh.vertices.push_back(vertices_[i]);
      } else if (representative_[i] == static_cast<int>(i)) {
        ++report_.unused_vertices_removed;
      }
    }
    for (auto& f : faces_)
      for (int& v : f) v = new_index[static_cast<std::size_t>(v)];
    result_.mesh.faces = std::move(faces_);
    result_.source_face = std::move(source_);
  }

  const std::vector<Eigen::Vector3d>& vertices_;
  const std::vector<std::vector<int>>& polygons_;
  const MeshCleanOptions& options_;
  const std::string& label_;
  LoadedMesh result_;
  MeshReport& report_ = result_.report;

  // Bounds and welding.
  Eigen::Vector3d lo_;               // bounding box corner, the weld grid's origin
  double diagonal_ = 0.0;            // bounding box diagonal, the scale of the tolerances
  std::vector<int> representative_;  // vertex -> the vertex it is welded to

  // Faces.
  double min_area_ = 0.0;  // triangles of at most this area are degenerate
  std::vector<std::array<int, 3>> faces_;
  std::vector<std::size_t> source_;  // face -> its input polygon

  // The kept faces' sorted corners: a duplicate is found in constant time, so a fan
  // of many faces around one vertex costs no more than any other mesh.
  struct TripleHash {
    std::size_t operator()(const std::array<int, 3>& t) const {
      std::uint64_t h = 1469598103934665603ull;
      for (int v : t) h = (h ^ static_cast<std::uint32_t>(v)) * 1099511628211ull;
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_set<std::array<int, 3>, TripleHash> seen_;

  // Edges and orientation.
  std::unordered_map<std::uint64_t, std::vector<EdgeUse>> uses_;
  std::vector<int> flip_;  // per face: -1 unvisited, 0 keep, 1 flip
};

}  // namespace

LoadedMesh CleanMesh(const std::vector<Eigen::Vector3d>& vertices,
                     const std::vector<std::vector<int>>& polygons, const MeshCleanOptions& options,
                     const std::string& label) {
  options.Check();
  return MeshCleaner(vertices, polygons, options, label).Run();
}

LoadedMesh LoadMesh(const std::filesystem::path& path, const MeshCleanOptions& options) {
  const PolygonSoup soup = ReadPolygonSoup(path);
  if (soup.polygons.empty()) throw InputError(path.string(), "the mesh has no faces");
  return CleanMesh(soup.vertices, soup.polygons, options, path.string());
}

void SaveMesh(const TriangleMesh& mesh, const std::filesystem::path& path) {
  SilenceOpenMesh();
  OmPolyMesh om;
  std::vector<OpenMesh::VertexHandle> handles;
  handles.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) handles.push_back(om.add_vertex({v.x(), v.y(), v.z()}));
  for (const auto& f : mesh.faces) {
    std::vector<OpenMesh::VertexHandle> fh = {handles[static_cast<std::size_t>(f[0])],
                                              handles[static_cast<std::size_t>(f[1])],
                                              handles[static_cast<std::size_t>(f[2])]};
    if (!om.add_face(fh).is_valid()) {
      // A face OpenMesh cannot attach (non-manifold) is written with its own copies
      // of its vertices, as OpenMesh's importer does.
      for (auto& h : fh) h = om.add_vertex(om.point(h));
      om.add_face(fh);
    }
  }
  std::filesystem::path tmp =
      path.parent_path() /
      (path.stem().string() + ".tmp-" + std::to_string(::getpid()) + path.extension().string());
  OpenMesh::IO::Options write_options = OpenMesh::IO::Options::Binary;
  if (path.extension() == ".obj" || path.extension() == ".off") write_options = {};
  if (!OpenMesh::IO::write_mesh(om, tmp.string(), write_options, 17)) {
    std::error_code remove_error;
    std::filesystem::remove(tmp, remove_error);
    throw std::runtime_error(path.string() + ": cannot write mesh");
  }
  std::filesystem::rename(tmp, path);
}

std::vector<Eigen::Vector3d> FaceNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> normals(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d n =
        (mesh.Corner(f, 1) - mesh.Corner(f, 0)).cross(mesh.Corner(f, 2) - mesh.Corner(f, 0));
    const double len = n.norm();
    normals[f] = len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  }
  return normals;
}

std::vector<double> FaceAreas(const TriangleMesh& mesh) {
  std::vector<double> areas(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    areas[f] =
        0.5 *
        (mesh.Corner(f, 1) - mesh.Corner(f, 0)).cross(mesh.Corner(f, 2) - mesh.Corner(f, 0)).norm();
  }
  return areas;
}

std::vector<std::array<int, 3>> FaceNeighbours(const TriangleMesh& mesh) {
  std::vector<std::array<int, 3>> neighbours(mesh.faces.size(), {-1, -1, -1});
  const auto uses = EdgeUses(mesh.faces);
  for (const auto& [key, list] : uses) {
    if (list.size() != 2) continue;
    neighbours[static_cast<std::size_t>(list[0].face)][static_cast<std::size_t>(list[0].corner)] =
        list[1].face;
    neighbours[static_cast<std::size_t>(list[1].face)][static_cast<std::size_t>(list[1].corner)] =
        list[0].face;
  }
  return neighbours;
}

std::vector<int> BreadthFirstFaceOrder(const TriangleMesh& mesh,
                                       const std::vector<std::array<int, 3>>& neighbours,
                                       int seed_face) {
  const int n = static_cast<int>(mesh.faces.size());
  if (seed_face < 0 || seed_face >= n) {
    throw std::out_of_range("seed face " + std::to_string(seed_face) + " is not a face index");
  }
  // The seed's component, then the others from their lowest-index face.
  std::vector<int> starts(static_cast<std::size_t>(n) + 1);
  starts[0] = seed_face;
  std::iota(starts.begin() + 1, starts.end(), 0);
  return BreadthFirstFaceOrderWithin(starts, std::vector<char>(static_cast<std::size_t>(n), 1),
                                     neighbours);
}

namespace {

// Breadth first within `member` from the faces already in `order` (visited),
// appending to it.
void ContinueBreadthFirst(const std::vector<char>& member,
                          const std::vector<std::array<int, 3>>& neighbours,
                          std::vector<char>& visited, std::vector<int>& order, std::size_t head) {
  for (; head < order.size(); ++head) {
    for (const int g : neighbours[static_cast<std::size_t>(order[head])]) {
      if (g < 0 || !member[static_cast<std::size_t>(g)] || visited[static_cast<std::size_t>(g)])
        continue;
      visited[static_cast<std::size_t>(g)] = 1;
      order.push_back(g);
    }
  }
}

}  // namespace

std::vector<int> BreadthFirstFaceOrderFrom(const std::vector<int>& sources,
                                           const std::vector<int>& starts,
                                           const std::vector<char>& member,
                                           const std::vector<std::array<int, 3>>& neighbours) {
  std::vector<char> visited(member.size(), 0);
  std::vector<int> order;
  for (const int source : sources) {
    const auto s = static_cast<std::size_t>(source);
    if (!member[s] || visited[s]) continue;
    visited[s] = 1;
    order.push_back(source);
  }
  ContinueBreadthFirst(member, neighbours, visited, order, 0);
  for (const int start : starts) {
    const auto s = static_cast<std::size_t>(start);
    if (!member[s] || visited[s]) continue;
    const std::size_t head = order.size();
    visited[s] = 1;
    order.push_back(start);
    ContinueBreadthFirst(member, neighbours, visited, order, head);
  }
  return order;
}

std::vector<int> BreadthFirstFaceOrderWithin(const std::vector<int>& starts,
                                             const std::vector<char>& member,
                                             const std::vector<std::array<int, 3>>& neighbours) {
  return BreadthFirstFaceOrderFrom({}, starts, member, neighbours);
}

Eigen::Vector3d BoundingBoxCentre(const TriangleMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
  return box.isEmpty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(box.center());
}

MeshStats ComputeMeshStats(const TriangleMesh& mesh) {
  MeshStats s;
  s.vertices = mesh.vertices.size();
  s.faces = mesh.faces.size();
  const auto uses = EdgeUses(mesh.faces);
  s.edges = uses.size();
  double edge_length_sum = 0.0;
  for (const auto& [key, list] : uses) {
    if (list.size() == 1) ++s.boundary_edges;
    const auto& f = mesh.faces[static_cast<std::size_t>(list[0].face)];
    edge_length_sum +=
        (mesh.vertices[static_cast<std::size_t>(f[static_cast<std::size_t>(list[0].corner)])] -
         mesh.vertices[static_cast<std::size_t>(
             f[static_cast<std::size_t>((list[0].corner + 1) % 3)])])
            .norm();
  }
  s.mean_edge_length = s.edges ? edge_length_sum / static_cast<double>(s.edges) : 0.0;
  for (double a : FaceAreas(mesh)) s.surface_area += a;
  if (!mesh.vertices.empty()) {
    s.bbox_min = s.bbox_max = mesh.vertices[0];
    for (const auto& v : mesh.vertices) {
      s.bbox_min = s.bbox_min.cwiseMin(v);
      s.bbox_max = s.bbox_max.cwiseMax(v);
    }
  }
  if (!mesh.faces.empty()) {
    const auto neighbours = FaceNeighbours(mesh);
    const auto order = BreadthFirstFaceOrder(mesh, neighbours, 0);
    // Count component starts: a face whose BFS predecessor set is empty starts one.
    std::vector<char> seen(mesh.faces.size(), 0);
    for (int f : order) {
      bool connected = false;
      for (int g : neighbours[static_cast<std::size_t>(f)]) {
        connected = connected || (g >= 0 && seen[static_cast<std::size_t>(g)]);
      }
      if (!connected) ++s.components;
      seen[static_cast<std::size_t>(f)] = 1;
    }
  }
  return s;
}

Eigen::Vector3d SmoothNormalAt(const TriangleMesh& mesh,
                               const std::vector<Eigen::Vector3d>& vertex_normals, std::size_t f,
                               const Eigen::Vector3d& barycentric) {
  const auto& v = mesh.faces[f];
  return (barycentric[0] * vertex_normals[static_cast<std::size_t>(v[0])] +
          barycentric[1] * vertex_normals[static_cast<std::size_t>(v[1])] +
          barycentric[2] * vertex_normals[static_cast<std::size_t>(v[2])])
      .normalized();
}

std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> n(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d a =
        (mesh.Corner(f, 1) - mesh.Corner(f, 0)).cross(mesh.Corner(f, 2) - mesh.Corner(f, 0));
    for (int v : mesh.faces[f]) n[static_cast<std::size_t>(v)] += a;
  }
  for (auto& v : n) v = v.norm() > 0 ? v.normalized() : Eigen::Vector3d::UnitZ();
  return n;
}

TriangleMesh SubdivideMidpoint(const TriangleMesh& mesh) {
  TriangleMesh out;
  out.vertices = mesh.vertices;
  std::map<std::pair<int, int>, int> midpoint;
  auto mid = [&](int a, int b) {
    const std::pair<int, int> key(std::min(a, b), std::max(a, b));
    const auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    out.vertices.push_back(0.5 * (mesh.vertices[static_cast<std::size_t>(a)] +
                                  mesh.vertices[static_cast<std::size_t>(b)]));
    const int id = static_cast<int>(out.vertices.size() - 1);
    midpoint.emplace(key, id);
    return id;
  };
  for (const auto& f : mesh.faces) {
    const int a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
    out.faces.push_back({f[0], a, c});
    out.faces.push_back({a, f[1], b});
    out.faces.push_back({c, b, f[2]});
    out.faces.push_back({a, b, c});
  }
  return out;
}

}  // namespace texlume::mesh
