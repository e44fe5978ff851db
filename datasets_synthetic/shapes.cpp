#include "datasets_synthetic/shapes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

namespace texlume::datasets {
namespace {

// Shape dimensions (world units).
constexpr double kSphereRadius = 1.0;
constexpr double kCylinderRadius = 0.6;
constexpr double kCylinderHeight = 1.6;
constexpr double kPlaneSize = 2.0;
constexpr double kTorusMajor = 0.8;
constexpr double kTorusMinor = 0.35;

SurfacePoint Complete(SurfacePoint p) {
  const Eigen::Vector3d n = p.d_du.cross(p.d_dv);
  if (n.norm() > 1e-12) p.normal = n.normalized();
  return p;
}

}  // namespace

std::string_view SceneShapeName(SceneShape shape) {
  switch (shape) {
    case SceneShape::kSphere:
      return "sphere";
    case SceneShape::kCylinder:
      return "cylinder";
    case SceneShape::kPlane:
      return "plane";
    case SceneShape::kTorus:
      return "torus";
  }
  return "?";
}

std::optional<SceneShape> SceneShapeFromName(std::string_view name) {
  for (auto s :
       {SceneShape::kSphere, SceneShape::kCylinder, SceneShape::kPlane, SceneShape::kTorus}) {
    if (SceneShapeName(s) == name) return s;
  }
  return std::nullopt;
}

std::vector<SurfacePatch> ShapePatches(SceneShape shape) {
  std::vector<SurfacePatch> patches;
  switch (shape) {
    case SceneShape::kPlane: {
      SurfacePatch p;
      p.u0 = p.v0 = -kPlaneSize / 2;
      p.u1 = p.v1 = kPlaneSize / 2;
      p.eval = [](double u, double v) {
        SurfacePoint s;
        s.position = {u, v, 0};
        return s;
      };
      patches.push_back(p);
      break;
    }
    case SceneShape::kSphere: {
      // u = R * longitude (wraps), v = R * latitude: isometric along meridians and
      // the equator, stretched towards the poles.
      SurfacePatch p;
      p.u0 = 0;
      p.u1 = 2 * std::numbers::pi * kSphereRadius;
      p.v0 = -std::numbers::pi / 2 * kSphereRadius;
      p.v1 = std::numbers::pi / 2 * kSphereRadius;
      p.periodic_u = true;
      p.eval = [](double u, double v) {
        const double phi = u / kSphereRadius, lat = v / kSphereRadius;
        SurfacePoint s;
        s.position = kSphereRadius * Eigen::Vector3d(std::cos(lat) * std::cos(phi),
                                                     std::cos(lat) * std::sin(phi), std::sin(lat));
        s.d_du = Eigen::Vector3d(-std::cos(lat) * std::sin(phi), std::cos(lat) * std::cos(phi), 0);
        s.d_dv = Eigen::Vector3d(-std::sin(lat) * std::cos(phi), -std::sin(lat) * std::sin(phi),
                                 std::cos(lat));
        s = Complete(s);
        s.normal = s.position.normalized();
        return s;
      };
      patches.push_back(p);
      break;
    }
    case SceneShape::kCylinder: {
      SurfacePatch side;
      side.u0 = 0;
      side.u1 = 2 * std::numbers::pi * kCylinderRadius;
      side.v0 = -kCylinderHeight / 2;
      side.v1 = kCylinderHeight / 2;
      side.periodic_u = true;
      side.eval = [](double u, double v) {
        const double phi = u / kCylinderRadius;
        SurfacePoint s;
        s.position = {kCylinderRadius * std::cos(phi), kCylinderRadius * std::sin(phi), v};
        s.d_du = {-std::sin(phi), std::cos(phi), 0};
        s.d_dv = {0, 0, 1};
        return Complete(s);
      };
      patches.push_back(side);
      for (int top = 0; top < 2; ++top) {
        SurfacePatch cap;
        cap.domain = SurfacePatch::Domain::kDisk;
        cap.u0 = cap.v0 = -kCylinderRadius;
        cap.u1 = cap.v1 = kCylinderRadius;
        cap.eval = [top](double u, double v) {
          SurfacePoint s;
          // Top: (u, v) = (x, y); bottom: (u, v) = (x, -y) so that d_du x d_dv = -Z.
          s.position = {u, top ? v : -v, top ? kCylinderHeight / 2 : -kCylinderHeight / 2};
          s.d_du = {1, 0, 0};
          s.d_dv = {0, top ? 1.0 : -1.0, 0};
          return Complete(s);
        };
        patches.push_back(cap);
      }
      break;
    }
    case SceneShape::kTorus: {
      SurfacePatch p;
      p.u0 = 0;
      p.u1 = 2 * std::numbers::pi * kTorusMajor;
      p.v0 = 0;
      p.v1 = 2 * std::numbers::pi * kTorusMinor;
      p.periodic_u = p.periodic_v = true;
      p.eval = [](double u, double v) {
        const double phi = u / kTorusMajor, theta = v / kTorusMinor;
        const double ring = kTorusMajor + kTorusMinor * std::cos(theta);
        SurfacePoint s;
        s.position = {ring * std::cos(phi), ring * std::sin(phi), kTorusMinor * std::sin(theta)};
        s.d_du = (ring / kTorusMajor) * Eigen::Vector3d(-std::sin(phi), std::cos(phi), 0);
        s.d_dv = {-std::sin(theta) * std::cos(phi), -std::sin(theta) * std::sin(phi),
                  std::cos(theta)};
        return Complete(s);
      };
      patches.push_back(p);
      break;
    }
  }
  return patches;
}

mesh::TriangleMesh CoarseMesh(SceneShape shape) {
  switch (shape) {
    case SceneShape::kSphere:
      return MakeIcosphere(3, kSphereRadius);
    case SceneShape::kCylinder:
      return MakeCylinder(48, 12, kCylinderRadius, kCylinderHeight);
    case SceneShape::kPlane:
      return MakeGridPlane(16, kPlaneSize);
    case SceneShape::kTorus:
      return MakeTorus(48, 20, kTorusMajor, kTorusMinor);
  }
  return {};
}

mesh::TriangleMesh ShapeMeshWithFaces(SceneShape shape, std::int64_t target_faces) {
  const double n = static_cast<double>(std::max<std::int64_t>(target_faces, 1));
  // Cells about square: segments around / along = circumference / length.
  const auto segments = [](double value, int least) {
    return std::max(least, static_cast<int>(std::lround(value)));
  };
  switch (shape) {
    case SceneShape::kSphere: {
      int level = 0;  // 20 * 4^level nearest n on a log scale
      while (level < 10 && 20.0 * std::pow(4.0, level) * 2.0 < n) ++level;
      return MakeIcosphere(level, kSphereRadius);
    }
    case SceneShape::kCylinder: {
      // 2 * around * along (side) + about around^2 / pi (the caps' rings) faces.
      const double aspect = 2 * std::numbers::pi * kCylinderRadius / kCylinderHeight;
      const int along =
          segments(std::sqrt(n / (2 * aspect + aspect * aspect / std::numbers::pi)), 1);
      return MakeColumn(segments(aspect * along, 3), along, kCylinderRadius, kCylinderHeight);
    }
    case SceneShape::kPlane:
      return MakeGridPlane(segments(std::sqrt(n / 2), 1), kPlaneSize);
    case SceneShape::kTorus: {
      const double aspect = kTorusMajor / kTorusMinor;  // 2 * around * tube faces
      const int tube = segments(std::sqrt(n / (2 * aspect)), 3);
      return MakeTorus(segments(n / (2.0 * tube), 3), tube, kTorusMajor, kTorusMinor);
    }
  }
  return {};
}

mesh::TriangleMesh MakeTorus(int around, int tube, double major, double minor) {
  mesh::TriangleMesh mesh;
  for (int j = 0; j < tube; ++j) {
    const double theta = 2 * std::numbers::pi * j / tube;
    for (int i = 0; i < around; ++i) {
      const double phi = 2 * std::numbers::pi * i / around;
      const double ring = major + minor * std::cos(theta);
      mesh.vertices.emplace_back(ring * std::cos(phi), ring * std::sin(phi),
                                 minor * std::sin(theta));
    }
  }
  auto at = [&](int i, int j) { return (j % tube) * around + (i % around); };
  for (int j = 0; j < tube; ++j) {
    for (int i = 0; i < around; ++i) {
      mesh.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return mesh;
}

mesh::TriangleMesh MakeCrossedPlanes(int segments, double size) {
  if (segments % 2 != 0) throw std::invalid_argument("crossed planes need an even segment count");
  const mesh::TriangleMesh a = MakeGridPlane(segments, size);
  mesh::TriangleMesh out = a;
  // The second plane's vertices: those on the line are the first's.
  std::vector<int> second(a.vertices.size());
  for (std::size_t k = 0; k < a.vertices.size(); ++k) {
    const Eigen::Vector3d& v = a.vertices[k];
    if (std::abs(v.y()) < 1e-12) {
      second[k] = static_cast<int>(k);
      continue;
    }
    second[k] = static_cast<int>(out.vertices.size());
    out.vertices.emplace_back(v.x(), 0.0, v.y());
  }
  for (const auto& f : a.faces)
    out.faces.push_back({second[static_cast<std::size_t>(f[0])],
                         second[static_cast<std::size_t>(f[1])],
                         second[static_cast<std::size_t>(f[2])]});
  return out;
}

mesh::TriangleMesh JoinMeshes(const mesh::TriangleMesh& a, const mesh::TriangleMesh& b) {
  mesh::TriangleMesh out = a;
  const int offset = static_cast<int>(a.vertices.size());
  out.vertices.insert(out.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& f : b.faces) out.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
  return out;
}

mesh::TriangleMesh MakeScanLikeMesh(int subdivisions, double radius, double relief, unsigned seed) {
  mesh::TriangleMesh mesh = MakeIcosphere(subdivisions, 1.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double edge = (mesh.Corner(0, 1) - mesh.Corner(0, 0)).norm();
  for (Eigen::Vector3d& v : mesh.vertices) {
    const Eigen::Vector3d n = v.normalized();
    // Drawn one at a time: a call's arguments are evaluated in an unspecified order.
    const double dz = u(rng), dy = u(rng), dx = u(rng);
    const Eigen::Vector3d d(dx, dy, dz);
    v = (v + (edge / 3.0) * (d - d.dot(n) * n)).normalized();
  }
  std::vector<std::pair<Eigen::Vector3d, double>> bumps;  // centre on the sphere, height
  for (int k = 0; relief > 0 && k < 8; ++k) {
    const double z = u(rng), y = u(rng), x = u(rng), h = u(rng);
    bumps.emplace_back(Eigen::Vector3d(x, y, z).normalized(), h);
  }
  for (Eigen::Vector3d& v : mesh.vertices) {
    double r = 1.0;
    for (const auto& [centre, height] : bumps)
      r += relief * height * std::exp(-(v - centre).squaredNorm() / 0.5);
    v *= radius * r;
  }
  return mesh;
}

mesh::TriangleMesh MakeIcosphere(int subdivisions, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  mesh::TriangleMesh mesh;
  mesh.vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                   {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  mesh.faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& v : mesh.vertices) v.normalize();
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      mesh.vertices.push_back(
          (mesh.vertices[static_cast<std::size_t>(a)] + mesh.vertices[static_cast<std::size_t>(b)])
              .normalized());
      const int index = static_cast<int>(mesh.vertices.size()) - 1;
      midpoint[key] = index;
      return index;
    };
    std::vector<std::array<int, 3>> faces;
    for (const auto& f : mesh.faces) {
      const int a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      faces.push_back({f[0], a, c});
      faces.push_back({f[1], b, a});
      faces.push_back({f[2], c, b});
      faces.push_back({a, b, c});
    }
    mesh.faces = std::move(faces);
  }
  for (auto& v : mesh.vertices) v *= radius;
  return mesh;
}

mesh::TriangleMesh MakeCylinder(int around, int along, double radius, double height) {
  mesh::TriangleMesh mesh;
  for (int j = 0; j <= along; ++j) {
    const double z = -height / 2 + height * j / along;
    for (int i = 0; i < around; ++i) {
      const double a = 2 * std::numbers::pi * i / around;
      mesh.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), z);
    }
  }
  auto ring = [&](int i, int j) { return j * around + (i % around); };
  for (int j = 0; j < along; ++j) {
    for (int i = 0; i < around; ++i) {
      mesh.faces.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      mesh.faces.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0, 0, -height / 2);
  const int top = bottom + 1;
  mesh.vertices.emplace_back(0, 0, height / 2);
  for (int i = 0; i < around; ++i) {
    mesh.faces.push_back({bottom, ring(i + 1, 0), ring(i, 0)});
    mesh.faces.push_back({top, ring(i, along), ring(i + 1, along)});
  }
  return mesh;
}

namespace {

// Vertices of a ring of `count` at `radius` and height z, from angle 0 counter-clockwise.
std::vector<int> AddRing(mesh::TriangleMesh& mesh, int count, double radius, double z) {
  std::vector<int> ring;
  for (int i = 0; i < count; ++i) {
    const double a = 2 * std::numbers::pi * i / count;
    ring.push_back(static_cast<int>(mesh.vertices.size()));
    mesh.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), z);
  }
  return ring;
}

// The triangles between two concentric rings (both from angle 0, counter-clockwise),
// advancing along whichever ring's next vertex comes first: facing +Z when `up`.
void ZipRings(mesh::TriangleMesh& mesh, const std::vector<int>& inner,
              const std::vector<int>& outer, bool up) {
  const auto ni = inner.size(), no = outer.size();
  const auto face = [&](int a, int b, int c) {
    mesh.faces.push_back(up ? std::array<int, 3>{a, b, c} : std::array<int, 3>{a, c, b});
  };
  std::size_t i = 0, j = 0;
  while (i < ni || j < no) {
    const double next_inner = static_cast<double>(i + 1) / static_cast<double>(ni);
    const double next_outer = static_cast<double>(j + 1) / static_cast<double>(no);
    if (j < no && (i == ni || next_outer <= next_inner)) {
      face(inner[i % ni], outer[j], outer[(j + 1) % no]);
      ++j;
    } else {
      face(inner[i], outer[j % no], inner[(i + 1) % ni]);
      ++i;
    }
  }
}

// A disk cap on `rim` (a ring of the side): concentric rings of about square
// cells, fewer vertices towards the centre, closed by a small fan.
void AddDiskCap(mesh::TriangleMesh& mesh, const std::vector<int>& rim, double radius, double z,
                bool up) {
  const int around = static_cast<int>(rim.size());
  const int rings = std::max(1, static_cast<int>(std::lround(around / (2 * std::numbers::pi))));
  std::vector<int> outer = rim;
  for (int r = rings - 1; r >= 1; --r) {
    const int count = std::max(3, static_cast<int>(std::lround(around * r / double(rings))));
    const std::vector<int> inner = AddRing(mesh, count, radius * r / rings, z);
    ZipRings(mesh, inner, outer, up);
    outer = inner;
  }
  const int centre = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, z);
  for (std::size_t j = 0; j < outer.size(); ++j) {
    const int a = outer[j], b = outer[(j + 1) % outer.size()];
    mesh.faces.push_back(up ? std::array<int, 3>{centre, a, b} : std::array<int, 3>{centre, b, a});
  }
}

}  // namespace

mesh::TriangleMesh MakeColumn(int around, int along, double radius, double height) {
  mesh::TriangleMesh mesh;
  std::vector<std::vector<int>> rings;
  for (int j = 0; j <= along; ++j)
    rings.push_back(AddRing(mesh, around, radius, -height / 2 + height * j / along));
  // Seen from outside, (lower, upper, upper next) turns clockwise: "down".
  for (int j = 0; j < along; ++j) ZipRings(mesh, rings[j], rings[j + 1], false);
  AddDiskCap(mesh, rings.front(), radius, -height / 2, false);
  AddDiskCap(mesh, rings.back(), radius, height / 2, true);
  return mesh;
}

mesh::TriangleMesh MakeGridPlane(int segments, double size) {
  mesh::TriangleMesh mesh;
  for (int j = 0; j <= segments; ++j) {
    for (int i = 0; i <= segments; ++i) {
      mesh.vertices.emplace_back(-size / 2 + size * i / segments, -size / 2 + size * j / segments,
                                 0.0);
    }
  }
  auto at = [&](int i, int j) { return j * (segments + 1) + i; };
  for (int j = 0; j < segments; ++j) {
    for (int i = 0; i < segments; ++i) {
      mesh.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return mesh;
}

}  // namespace texlume::datasets
