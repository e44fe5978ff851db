// The mesh readers (mesh/mesh_readers.h): known answers in every format and
// encoding, and malformed files refused with the file named, never a crash or a
// hang (the cases OpenMesh's PLY reader crashed or hung on among them).
#include "mesh/mesh_readers.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "core/errors.h"
#include "mesh/mesh.h"
#include "tests/test_util.h"

namespace texlume::mesh {
namespace {

using testing::InputErrorMessage;

// A tetrahedron: 4 vertices, 4 faces, as every format below lists it.
const std::vector<Eigen::Vector3d> kTetraVertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const std::vector<std::vector<int>> kTetraFaces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

void ExpectTetra(const PolygonSoup& soup) {
  ASSERT_EQ(soup.vertices.size(), kTetraVertices.size());
  for (std::size_t i = 0; i < kTetraVertices.size(); ++i) {
    EXPECT_TRUE(soup.vertices[i].isApprox(kTetraVertices[i])) << i;
  }
  EXPECT_EQ(soup.polygons, kTetraFaces);
}

std::string AsciiPlyTetra() {
  return "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\n"
         "property float y\nproperty float z\nproperty uchar red\nelement face 4\n"
         "property list uchar int vertex_indices\nend_header\n"
         "0 0 0 9\n1 0 0 9\n0 1 0 9\n0 0 1 9\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
}

template <typename T>
void Put(std::string& out, T value, bool big_endian) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian) std::reverse(raw, raw + sizeof(T));
  out.append(raw, sizeof(T));
}

std::string BinaryPlyTetra(bool big_endian) {
  std::string out = std::string("ply\nformat ") +
                    (big_endian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                    "property double z\nelement face 4\nproperty list uchar uint vertex_indices\n"
                    "end_header\n";
  for (const auto& v : kTetraVertices)
    for (int c = 0; c < 3; ++c) Put<double>(out, v[c], big_endian);
  for (const auto& f : kTetraFaces) {
    Put<std::uint8_t>(out, 3, big_endian);
    for (int i : f) Put<std::uint32_t>(out, static_cast<std::uint32_t>(i), big_endian);
  }
  return out;
}

TEST(MeshReaders, PlyAsciiAndBinaryGiveTheSameMesh) {
  ExpectTetra(ParsePly(AsciiPlyTetra(), "t.ply"));
  ExpectTetra(ParsePly(BinaryPlyTetra(false), "t.ply"));
  ExpectTetra(ParsePly(BinaryPlyTetra(true), "t.ply"));
}

TEST(MeshReaders, MalformedPlyHeadersAreRefusedNamingTheFile) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"ply\nformat ascii 1.0\nproperty float x\nelement vertex 1\nend_header\n0\n", "before any"},
      {"ply\nformat ascii 1.0\nelement vertex\nproperty float x\nend_header\n", "element <name>"},
      {"ply\nformat ascii 1.0\nelement\nend_header\n", "element <name>"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "end_header"},
      {"ply\nformat ascii 1.0\nelement face 1\nproperty lst uchar int vertex_indices\n"
       "end_header\n",
       "property"},
      {"ply\nformat ascii 2.0\nend_header\n", "format"},
      {"plx\n", "not a PLY"},
      {"ply\nformat ascii 1.0\nelement vertex 2000000000\nproperty float x\nproperty float y\n"
       "property float z\nend_header\n0 0 0\n",
       "announces 2000000000"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n0 0\n",
       "'z'"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string& ply = text;  // a plain name: lambdas capture it (clang 14)
    const std::string message = InputErrorMessage([&] { ParsePly(ply, "bad.ply"); });
    EXPECT_NE(message.find("bad.ply"), std::string::npos) << text;
    EXPECT_NE(message.find(expected), std::string::npos) << text << " -> " << message;
  }
}

TEST(MeshReaders, TruncatedOrOutOfRangePlyBodiesAreRefused) {
  const std::string binary = BinaryPlyTetra(false);
  for (std::size_t keep : {binary.size() - 1, binary.size() - 20, binary.size() - 60}) {
    EXPECT_NE(InputErrorMessage([&] { ParsePly(binary.substr(0, keep), "cut.ply"); }), "") << keep;
  }
  std::string huge_index = AsciiPlyTetra();
  huge_index.replace(huge_index.find("3 1 2 3"), 7, "3 1 2 4000000000");
  EXPECT_NE(InputErrorMessage([&] { ParsePly(huge_index, "i.ply"); }).find("not a valid index"),
            std::string::npos);
  std::string huge_list = AsciiPlyTetra();
  huge_list.replace(huge_list.find("3 1 2 3"), 7, "4000000000 1 2 3");
  EXPECT_NE(InputErrorMessage([&] { ParsePly(huge_list, "l.ply"); }), "");
  std::string nan = AsciiPlyTetra();
  nan.replace(nan.find("0 0 1 9"), 7, "0 0 nan 9");
  EXPECT_NE(InputErrorMessage([&] { ParsePly(nan, "n.ply"); }).find("finite"), std::string::npos);
}

TEST(MeshReaders, ObjReadsEveryCornerFormAndNegativeIndices) {
  const std::string obj =
      "# tetra\nmtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n"
      "o t\ng g\nusemtl m\nf 1 3 2\nf 1/1 2/1 4/1\nf 1//1 4//1 3//1\nf -3/1/1 -2/1/1 -1/1/1\n";
  ExpectTetra(ParseObj(obj, "t.obj"));
  EXPECT_NE(InputErrorMessage([] { ParseObj("v 0 0 1e400\n", "b.obj"); }).find("b.obj:1"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([] { ParseObj("v 0 0 0\nf 0 1 1\n", "b.obj"); }).find("index 0"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([] { ParseObj("v 0 0 0\nf -5 1 1\n", "b.obj"); }), "");
  EXPECT_NE(InputErrorMessage([] { ParseObj("v 0 0\n", "b.obj"); }), "");
}

TEST(MeshReaders, OffWithCommentsColoursAndCountsOnTheKeywordLine) {
  const std::string off =
      "OFF 4 4 6\n# a comment\n0 0 0\n1 0 0\n0 1 0 # trailing\n0 0 1\n"
      "3 0 2 1 255 0 0\n3 0 1 3\n\n3 0 3 2\n3 1 2 3\n";
  ExpectTetra(ParseOff(off, "t.off"));
  EXPECT_NE(InputErrorMessage([] {
              ParseOff("OFF\n2000000000 1 0\n0 0 0\n", "b.off");
            }).find("announces 2000000000"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([] { ParseOff("OFF BINARY\n", "b.off"); }).find("binary"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([] {
              ParseOff("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n5 0 1 2\n", "b.off");
            }).find("fewer"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([] { ParseOff("PLY\n", "b.off"); }).find("not an OFF"),
            std::string::npos);
}

std::string BinaryStlTetra() {
  std::string out(80, ' ');
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(kTetraFaces.size()), false);
  for (const auto& f : kTetraFaces) {
    for (int c = 0; c < 3; ++c) Put<float>(out, 0.0f, false);  // the normal, unused
    for (int i : f)
      for (int c = 0; c < 3; ++c)
        Put<float>(out, static_cast<float>(kTetraVertices[static_cast<std::size_t>(i)][c]), false);
    Put<std::uint16_t>(out, 0, false);
  }
  return out;
}

TEST(MeshReaders, StlBinaryAndAsciiWeldCornersAtOnePosition) {
  const PolygonSoup binary = ParseStl(BinaryStlTetra(), "t.stl");
  EXPECT_EQ(binary.vertices.size(), 4u);
  EXPECT_EQ(binary.polygons.size(), 4u);
  std::string ascii = "solid t\n";
  for (const auto& f : kTetraFaces) {
    ascii += "facet normal 0 0 0\nouter loop\n";
    for (int i : f) {
      const auto& v = kTetraVertices[static_cast<std::size_t>(i)];
      ascii += "vertex " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " +
               std::to_string(v.z()) + "\n";
    }
    ascii += "endloop\nendfacet\n";
  }
  ascii += "endsolid t\n";
  const PolygonSoup text = ParseStl(ascii, "t.stl");
  EXPECT_EQ(text.vertices.size(), 4u);
  EXPECT_EQ(text.polygons, binary.polygons);
  std::string lying = BinaryStlTetra();
  lying[80] = 100;  // announces 100 triangles
  EXPECT_NE(InputErrorMessage([&] { ParseStl(lying, "b.stl"); }).find("announces 100"),
            std::string::npos);
}

TEST(MeshReaders, LoadMeshRefusesOtherExtensionsAndMissingFiles) {
  testing::TempDir tmp;
  testing::WriteText(tmp / "m.xyz", "0 0 0\n");
  EXPECT_NE(InputErrorMessage([&] { LoadMesh(tmp / "m.xyz"); }).find("unsupported"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([&] { LoadMesh(tmp / "none.ply"); }).find("none.ply"),
            std::string::npos);
  testing::WriteText(tmp / "t.PLY", AsciiPlyTetra());
  EXPECT_EQ(LoadMesh(tmp / "t.PLY").mesh.NumFaces(), 4u);
}

// A fan of many triangles around one vertex is repaired (duplicate faces found by
// hashing, not by scanning the faces of the fan's smallest vertex).
TEST(MeshReaders, FanAroundOneVertexKeepsEveryFaceAndDropsRepeats) {
  const int n = 20000;
  std::vector<Eigen::Vector3d> vertices = {Eigen::Vector3d::Zero()};
  std::vector<std::vector<int>> polygons;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    vertices.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  for (int i = 0; i < n; ++i) polygons.push_back({0, 1 + i, 1 + (i + 1) % n});
  polygons.push_back({0, 2, 1});  // a repeat of face 0, the other way round
  const LoadedMesh mesh = CleanMesh(vertices, polygons, {}, "fan");
  EXPECT_EQ(mesh.mesh.NumFaces(), static_cast<std::size_t>(n));
  EXPECT_EQ(mesh.report.duplicate_faces_removed, 1u);
}

}  // namespace
}  // namespace texlume::mesh
