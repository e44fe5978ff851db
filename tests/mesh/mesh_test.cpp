#include "mesh/mesh.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "datasets_synthetic/object_scene.h"
#include "tests/test_util.h"

namespace texlume::mesh {
namespace {

using testing::TempDir;
using testing::WriteText;

double SignedVolume(const mesh::TriangleMesh& m) {
  double v = 0;
  for (std::size_t f = 0; f < m.NumFaces(); ++f) {
    v += m.Corner(f, 0).dot(m.Corner(f, 1).cross(m.Corner(f, 2))) / 6.0;
  }
  return v;
}

// A tetrahedron with outward faces.
std::vector<Eigen::Vector3d> TetraVertices() {
  return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
}
std::vector<std::vector<int>> TetraFaces() { return {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}; }

TEST(Mesh, EveryFormatRoundTripsThroughOpenMesh) {
  TempDir tmp;
  const mesh::TriangleMesh sphere = datasets::MakeIcosphere(2, 1.5);
  for (const std::string ext : {".ply", ".obj", ".off", ".stl"}) {
    const auto path = tmp / ("sphere" + ext);
    mesh::SaveMesh(sphere, path);
    const mesh::LoadedMesh loaded = mesh::LoadMesh(path);
    EXPECT_EQ(loaded.mesh.NumFaces(), sphere.NumFaces()) << ext;
    EXPECT_EQ(loaded.mesh.NumVertices(), sphere.NumVertices()) << ext;
    const mesh::MeshStats stats = mesh::ComputeMeshStats(loaded.mesh);
    EXPECT_EQ(stats.boundary_edges, 0u) << ext;
    EXPECT_EQ(stats.components, 1u) << ext;
    EXPECT_EQ(loaded.report.non_manifold_edges, 0u) << ext;
    EXPECT_EQ(loaded.report.faces_flipped, 0u) << ext;
    EXPECT_GT(SignedVolume(loaded.mesh), 0.0) << ext;
    if (ext != ".stl") {  // STL stores unshared corners, which are welded on load
      EXPECT_TRUE(loaded.report.Problems().empty()) << ext;
      EXPECT_LT((loaded.mesh.vertices[5] - sphere.vertices[5]).norm(), 1e-6) << ext;
    }
  }
}

TEST(Mesh, DuplicateVerticesDegenerateAndDuplicateFacesAreRepaired) {
  auto vertices = TetraVertices();
  vertices.push_back({1, 0, 0});    // 4: duplicate of 1
  vertices.push_back({0.5, 0, 0});  // 5: on edge 0-1 (collinear face)
  vertices.push_back({9, 9, 9});    // 6: unused
  auto faces = TetraFaces();
  faces[3] = {4, 2, 3};        // uses the duplicate vertex
  faces.push_back({0, 0, 3});  // repeated corner
  faces.push_back({0, 5, 1});  // zero area
  faces.push_back({2, 3, 1});  // same vertices as face 3 once welded
  const mesh::LoadedMesh m = mesh::CleanMesh(vertices, faces, {}, "soup");
  EXPECT_EQ(m.report.duplicate_vertices_merged, 1u);
  EXPECT_EQ(m.report.degenerate_faces_removed, 2u);
  EXPECT_EQ(m.report.duplicate_faces_removed, 1u);
  EXPECT_EQ(m.report.unused_vertices_removed, 2u);  // 5 and 6
  EXPECT_EQ(m.mesh.NumFaces(), 4u);
  EXPECT_EQ(m.mesh.NumVertices(), 4u);
  EXPECT_EQ(mesh::ComputeMeshStats(m.mesh).boundary_edges, 0u);
  EXPECT_EQ(m.source_face, (std::vector<std::size_t>{0, 1, 2, 3}));
}

TEST(Mesh, InconsistentOrientationIsFixedOutwards) {
  auto faces = TetraFaces();
  std::swap(faces[1][1], faces[1][2]);  // one face flipped
  mesh::LoadedMesh m = mesh::CleanMesh(TetraVertices(), faces, {}, "soup");
  EXPECT_EQ(m.report.inconsistently_oriented_edges, 3u);
  EXPECT_EQ(m.report.faces_flipped, 1u);
  EXPECT_GT(SignedVolume(m.mesh), 0.0);

  // A closed mesh that is consistently inward is turned outwards.
  faces = TetraFaces();
  for (auto& f : faces) std::swap(f[1], f[2]);
  m = mesh::CleanMesh(TetraVertices(), faces, {}, "soup");
  EXPECT_EQ(m.report.inconsistently_oriented_edges, 0u);
  EXPECT_EQ(m.report.faces_flipped, 4u);
  EXPECT_GT(SignedVolume(m.mesh), 0.0);

  // Without repair the orientation is reported but kept.
  mesh::MeshCleanOptions keep;
  keep.fix_orientation = false;
  m = mesh::CleanMesh(TetraVertices(), faces, keep, "soup");
  EXPECT_EQ(m.report.faces_flipped, 0u);
  EXPECT_LT(SignedVolume(m.mesh), 0.0);
}

TEST(Mesh, NonManifoldEdgesAreCountedAndHaveNoNeighbour) {
  // Three triangles sharing the edge 0-1 (a "book" with three pages).
  const std::vector<Eigen::Vector3d> v = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  const std::vector<std::vector<int>> f = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const mesh::LoadedMesh m = mesh::CleanMesh(v, f, {}, "book");
  EXPECT_EQ(m.report.non_manifold_edges, 1u);
  const auto neighbours = mesh::FaceNeighbours(m.mesh);
  for (const auto& n : neighbours) EXPECT_EQ(n[0], -1);
  EXPECT_FALSE(m.report.Problems().empty());
}

TEST(Mesh, PolygonsAreFanTriangulated) {
  const std::vector<Eigen::Vector3d> v = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const mesh::LoadedMesh m = mesh::CleanMesh(v, {{0, 1, 2, 3}}, {}, "quad");
  EXPECT_EQ(m.report.polygons_triangulated, 1u);
  EXPECT_EQ(m.mesh.NumFaces(), 2u);
}

TEST(Mesh, NormalsAreasAndNeighboursKnownAnswers) {
  const mesh::LoadedMesh m = mesh::CleanMesh(TetraVertices(), TetraFaces(), {}, "tetra");
  const auto normals = mesh::FaceNormals(m.mesh);
  const auto areas = mesh::FaceAreas(m.mesh);
  EXPECT_TRUE(normals[0].isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_NEAR(areas[0], 0.5, 1e-15);
  EXPECT_NEAR(areas[3], std::sqrt(3.0) / 2.0, 1e-15);
  const auto neighbours = mesh::FaceNeighbours(m.mesh);
  // Face 0 = (0,2,1): across (0,2) is face 2 (0,3,2); across (2,1) face 3; across (1,0) face 1.
  EXPECT_EQ(neighbours[0], (std::array<int, 3>{2, 3, 1}));
  for (std::size_t f = 0; f < 4; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int g = neighbours[f][static_cast<std::size_t>(k)];
      ASSERT_GE(g, 0);
      const auto& back = neighbours[static_cast<std::size_t>(g)];
      EXPECT_NE(std::find(back.begin(), back.end(), static_cast<int>(f)), back.end());
    }
  }
}

TEST(Mesh, BreadthFirstOrderGivesEveryFaceAProcessedNeighbour) {
  mesh::TriangleMesh mesh = datasets::MakeIcosphere(2, 1.0);
  // A second component: a shifted copy.
  const int offset = static_cast<int>(mesh.NumVertices());
  const mesh::TriangleMesh copy = datasets::MakeIcosphere(1, 0.5);
  for (const auto& v : copy.vertices) mesh.vertices.push_back(v + Eigen::Vector3d(5, 0, 0));
  for (const auto& f : copy.faces)
    mesh.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
  const auto neighbours = mesh::FaceNeighbours(mesh);
  const auto order = mesh::BreadthFirstFaceOrder(mesh, neighbours, 17);
  ASSERT_EQ(order.size(), mesh.NumFaces());
  EXPECT_EQ(order[0], 17);
  std::vector<char> done(mesh.NumFaces(), 0);
  int component_starts = 0;
  for (int f : order) {
    ASSERT_FALSE(done[static_cast<std::size_t>(f)]) << "face twice";
    bool has_done_neighbour = false;
    for (int g : neighbours[static_cast<std::size_t>(f)]) {
      has_done_neighbour |= g >= 0 && done[static_cast<std::size_t>(g)];
    }
    component_starts += has_done_neighbour ? 0 : 1;
    done[static_cast<std::size_t>(f)] = 1;
  }
  EXPECT_EQ(component_starts, 2);
  EXPECT_EQ(mesh::ComputeMeshStats(mesh).components, 2u);
  EXPECT_THROW(mesh::BreadthFirstFaceOrder(mesh, neighbours, -1), std::out_of_range);
}

TEST(MeshBadInput, UnparsableMissingAndOutOfRangeFilesAreNamed) {
  TempDir tmp;
  auto error_of = [](const std::filesystem::path& p) -> std::string {
    try {
      mesh::LoadMesh(p);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  WriteText(tmp / "garbage.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
            "end_header\nthis is not a number\n");
  WriteText(tmp / "out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n");
  WriteText(tmp / "no_faces.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  WriteText(tmp / "mesh.xyz", "1 2 3\n");
  WriteText(tmp / "nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  for (const std::string name :
       {"garbage.ply", "out_of_range.obj", "no_faces.off", "mesh.xyz", "missing.ply", "nan.obj"}) {
    const std::string error = error_of(tmp / name);
    EXPECT_FALSE(error.empty()) << name << " was accepted";
    EXPECT_NE(error.find(name), std::string::npos) << error;
  }
}

TEST(SubdivideMidpoint, SplitsEveryTriangleInFourAndWeldsMidpoints) {
  mesh::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  m.faces = {{0, 1, 2}, {1, 3, 2}};
  const mesh::TriangleMesh s = mesh::SubdivideMidpoint(m);
  EXPECT_EQ(s.faces.size(), 8u);
  EXPECT_EQ(s.vertices.size(), 9u);  // 4 + 5 edge midpoints, the shared one once
  double area = 0;
  for (double a : mesh::FaceAreas(s)) area += a;
  EXPECT_NEAR(area, 1.0, 1e-12);
}

}  // namespace
}  // namespace texlume::mesh
