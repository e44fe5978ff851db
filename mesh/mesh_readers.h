#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace texlume::mesh {

/// A mesh exactly as a file lists it: vertex positions and faces as vertex index
/// lists, in file order, before any repair (CleanMesh repairs it).
struct PolygonSoup {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> polygons;
};

/// Documented plausibility limits of the mesh readers. A file announcing more is
/// refused before anything is allocated by its counts; a count must also fit in
/// the bytes the file holds.
struct MeshReadLimits {
  static constexpr std::uint64_t kMaxVertices = 100'000'000;
  static constexpr std::uint64_t kMaxFaces = 200'000'000;
  static constexpr std::uint64_t kMaxCornersPerFace = 65'536;
  static constexpr std::size_t kMaxPlyHeaderBytes = 1 << 16;
  static constexpr std::uint64_t kMaxFileBytes = std::uint64_t{8} << 30;  // 8 GiB
};

/// The readers parse a whole file held in memory; `label` names it in errors.
/// Each throws InputError with the label (and the line, in text formats) for
/// anything malformed: a bad header, a count larger than the file can hold or than
/// MeshReadLimits, a token that is not a number, an index that is not an int, a
/// body cut short. None can crash, hang or allocate more than the file's size
/// times a small constant.

/// PLY (ascii, binary_little_endian, binary_big_endian): the `vertex` element's
/// x, y, z and the `face` element's `vertex_indices` (or `vertex_index`) list;
/// every other element and property is read past.
PolygonSoup ParsePly(std::string_view bytes, const std::string& label);
/// Wavefront OBJ: `v` and `f` lines (v, v/vt, v//vn, v/vt/vn, negative indices).
PolygonSoup ParseObj(std::string_view bytes, const std::string& label);
/// OFF (also COFF, NOFF, CNOFF, STOFF): counts, vertices, faces; the first three
/// numbers of a vertex line are its position, numbers after a face's indices
/// (colours) are ignored.
PolygonSoup ParseOff(std::string_view bytes, const std::string& label);
/// STL, binary (its triangle count matches the file size) or ASCII (`solid`);
/// corners at exactly the same position are one vertex, as STL readers do.
PolygonSoup ParseStl(std::string_view bytes, const std::string& label);

/// Reads a .ply, .obj, .off or .stl file (by extension, any case) with the parser
/// above. Throws InputError naming the file when it is missing, unreadable, of
/// another format or malformed.
PolygonSoup ReadPolygonSoup(const std::filesystem::path& path);

}  // namespace texlume::mesh
