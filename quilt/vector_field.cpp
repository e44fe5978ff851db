#include "quilt/vector_field.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/errors.h"
#include "core/json_io.h"

namespace texlume::quilt {
namespace {

/// Key vectors a field file may hold: the interpolation solves a dense system
/// of this side ("vectors at a few key faces", paper 004 §III-B).
constexpr std::size_t kMostKeys = 2048;

Eigen::Vector3d Centroid(const mesh::TriangleMesh& mesh, std::size_t f) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const int v : mesh.faces[f]) c += mesh.vertices[static_cast<std::size_t>(v)];
  return c / 3.0;
}

// The direction laid onto face f's plane, unit; the first edge when it lies
// along the normal.
Eigen::Vector3d InPlane(const mesh::TriangleMesh& mesh, std::size_t f, const Eigen::Vector3d& n,
                        const Eigen::Vector3d& d) {
  const Eigen::Vector3d t = d - d.dot(n) * n;
  if (t.norm() > 1e-6 * std::max(d.norm(), 1e-300)) return t.normalized();
  const auto& v = mesh.faces[f];
  return (mesh.vertices[static_cast<std::size_t>(v[1])] -
          mesh.vertices[static_cast<std::size_t>(v[0])])
      .normalized();
}

double RbfWidth(const std::vector<Eigen::Vector3d>& centres, const mesh::TriangleMesh& mesh) {
  if (centres.size() < 2) {
    Eigen::Vector3d lo = mesh.vertices[0], hi = lo;
    for (const Eigen::Vector3d& p : mesh.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    return std::max((hi - lo).norm(), 1e-12);
  }
  double sum = 0;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    double nearest = std::numeric_limits<double>::max();
    for (std::size_t j = 0; j < centres.size(); ++j)
      if (j != i) nearest = std::min(nearest, (centres[i] - centres[j]).norm());
    sum += nearest;
  }
  return std::max(sum / static_cast<double>(centres.size()), 1e-12);
}

KeyVector ReadKey(const nlohmann::json& item, const std::string& file, std::size_t index,
                  const mesh::TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& normals) {
  const std::string where = "vectors[" + std::to_string(index) + "]";
  if (!item.is_object() || !item.contains("face") || !item["face"].is_number_integer() ||
      !item.contains("direction") || !item["direction"].is_array() || item["direction"].size() != 3)
    throw InputError(file, where + " needs an integer \"face\" and a 3-vector \"direction\"");
  const long long face = item["face"].get<long long>();
  if (face < 0 || face >= static_cast<long long>(mesh.faces.size()))
    throw InputError(file, where + " names face " + std::to_string(face) + "; the mesh has " +
                               std::to_string(mesh.faces.size()) + " faces");
  KeyVector key;
  key.face = static_cast<int>(face);
  for (int c = 0; c < 3; ++c) {
    const nlohmann::json& x = item["direction"][static_cast<std::size_t>(c)];
    if (!x.is_number()) throw InputError(file, where + ": direction is not three numbers");
    key.direction_in_world[c] = x.get<double>();
  }
  const Eigen::Vector3d& n = normals[static_cast<std::size_t>(face)];
  const Eigen::Vector3d& d = key.direction_in_world;
  if (!d.allFinite() || !(d.norm() > 0))
    throw InputError(file, where + ": the direction is zero or not finite");
  if (!((d - d.dot(n) * n).norm() > 1e-6 * d.norm()))
    throw InputError(file, where + ": the direction is along face " + std::to_string(face) +
                               "'s normal, so it orients nothing");
  return key;
}

}  // namespace

std::vector<KeyVector> ReadFieldFile(const std::filesystem::path& path,
                                     const mesh::TriangleMesh& mesh) {
  const std::string file = path.string();
  const nlohmann::json doc = ReadJsonFile(path);
  if (!doc.is_object() || doc.value("format", "") != "texlume-field" || !doc.contains("vectors") ||
      !doc["vectors"].is_array())
    throw InputError(file,
                     "is not a field file ({\"format\": \"texlume-field\", \"vectors\": "
                     "[{\"face\": F, \"direction\": [x, y, z]}, ...]})");
  const nlohmann::json& vectors = doc["vectors"];
  if (vectors.empty()) throw InputError(file, "gives no vectors");
  if (vectors.size() > kMostKeys)
    throw InputError(file, "gives " + std::to_string(vectors.size()) + " vectors; at most " +
                               std::to_string(kMostKeys) + " key faces are interpolated");
  const std::vector<Eigen::Vector3d> normals = mesh::FaceNormals(mesh);
  std::vector<KeyVector> keys;
  for (std::size_t i = 0; i < vectors.size(); ++i)
    keys.push_back(ReadKey(vectors[i], file, i, mesh, normals));
  return keys;
}

std::vector<Eigen::Vector3d> InterpolateField(const mesh::TriangleMesh& mesh,
                                              const std::vector<KeyVector>& keys) {
  std::vector<Eigen::Vector3d> centres;
  for (const KeyVector& k : keys)
    centres.push_back(Centroid(mesh, static_cast<std::size_t>(k.face)));
  const double width = RbfWidth(centres, mesh);
  const std::vector<Eigen::Vector3d> normals = mesh::FaceNormals(mesh);
  const auto phi = [width](double r) { return std::exp(-(r * r) / (width * width)); };
  // Phi W = V: each key face gets its own (in-plane, unit) vector.
  const auto m = static_cast<Eigen::Index>(keys.size());
  Eigen::MatrixXd rbf(m, m), values(m, 3);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto ki = static_cast<std::size_t>(i);
    values.row(i) =
        InPlane(mesh, static_cast<std::size_t>(keys[ki].face),
                normals[static_cast<std::size_t>(keys[ki].face)], keys[ki].direction_in_world)
            .transpose();
    for (Eigen::Index j = 0; j < m; ++j)
      rbf(i, j) = phi((centres[ki] - centres[static_cast<std::size_t>(j)]).norm());
  }
  rbf.diagonal().array() += 1e-9;  // two keys on one face: still solvable
  const Eigen::MatrixXd weights = rbf.ldlt().solve(values);
  std::vector<Eigen::Vector3d> field(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d c = Centroid(mesh, f);
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (Eigen::Index k = 0; k < m; ++k)
      v += phi((c - centres[static_cast<std::size_t>(k)]).norm()) * weights.row(k).transpose();
    field[f] = InPlane(mesh, f, normals[f], v);
  }
  return field;
}

}  // namespace texlume::quilt
