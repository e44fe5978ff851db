#include "atlas/charts.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <set>
#include <tuple>
#include <unordered_map>

#include "atlas/chart_parts.h"
#include "core/check.h"
#include "core/errors.h"
#include "mesh/triangle_frame.h"

namespace texlume::atlas {
using namespace chart_parts;
namespace {

std::int64_t Key(int x, int y) {
  return (static_cast<std::int64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
}

/// Whether a flattening is usable: no flipped face, the chart's texel box
/// within `max_extent`, every face's stretch in [1/s, s] (after scaling the
/// chart to the surface's area, done here), and no two faces overlapping by
/// a texel centre. `uv` in texels.
bool ScaleAndCheck(const std::vector<synth::TrianglePatch>& patches, const std::vector<int>& faces,
                   double t, const ConformalChartOptions& options, std::vector<Corners>& uv) {
  double area_surface = 0, area_chart = 0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Corners c = FrameCornersTexels(patches[static_cast<std::size_t>(faces[i])], t);
    area_surface += 0.5 * Cross(c[1] - c[0], c[2] - c[0]);
    const double a = 0.5 * Cross(uv[i][1] - uv[i][0], uv[i][2] - uv[i][0]);
    if (!(a > 1e-9 * (1.0 + area_surface))) return false;  // flipped or collapsed
    area_chart += a;
  }
  const double scale = std::sqrt(area_surface / area_chart);
  if (!std::isfinite(scale)) return false;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max()), hi = -lo;
  for (Corners& q : uv)
    for (Eigen::Vector2d& p : q) {
      p *= scale;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  if ((hi - lo).maxCoeff() > options.max_extent_texels) return false;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const Corners c = FrameCornersTexels(patches[static_cast<std::size_t>(faces[i])], t);
    const Eigen::Vector2d sigma = SingularValues2(AffineBetween(faces[i], c, uv[i]).linear);
    if (sigma.x() > options.max_stretch || sigma.y() < 1.0 / options.max_stretch) return false;
  }
  // Overlaps: a texel centre more than half a texel inside two faces.
  const int w = static_cast<int>(std::ceil(hi.x() - lo.x())) + 1;
  const int h = static_cast<int>(std::ceil(hi.y() - lo.y())) + 1;
  std::vector<char> inside(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  for (const Corners& q0 : uv) {
    Corners q;
    for (std::size_t k = 0; k < 3; ++k) q[k] = q0[k] - lo;
    Eigen::Vector2d qlo = q[0].cwiseMin(q[1]).cwiseMin(q[2]);
    Eigen::Vector2d qhi = q[0].cwiseMax(q[1]).cwiseMax(q[2]);
    for (int y = std::max(0, static_cast<int>(qlo.y()));
         y <= std::min(h - 1, static_cast<int>(qhi.y())); ++y) {
      const auto [x_lo, x_hi] = mesh::TriangleRowSpan(q, y + 0.5, 0.0);
      if (x_lo > x_hi) continue;
      for (int x = std::max(0, static_cast<int>(std::floor(x_lo)));
           x <= std::min(w - 1, static_cast<int>(x_hi)); ++x) {
        if (mesh::SignedDistanceToTriangle(q, Eigen::Vector2d(x + 0.5, y + 0.5)) >= -0.5) continue;
        char& cell = inside[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                            static_cast<std::size_t>(x)];
        if (cell) return false;
        cell = 1;
      }
    }
  }
  return true;
}

/// Connected parts of `faces` over shared mesh edges.
std::vector<std::vector<int>> ConnectedParts(
    const std::vector<int>& faces, const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    std::vector<int>& mark, int& stamp) {
  ++stamp;
  const int in_set = stamp;
  for (const int f : faces) mark[static_cast<std::size_t>(f)] = in_set;
  ++stamp;
  const int seen = stamp;
  std::vector<std::vector<int>> parts;
  for (const int root : faces) {
    if (mark[static_cast<std::size_t>(root)] != in_set) continue;
    std::vector<int> part = {root};
    mark[static_cast<std::size_t>(root)] = seen;
    for (std::size_t i = 0; i < part.size(); ++i)
      for (const synth::Unfolding& u : unfoldings[static_cast<std::size_t>(part[i])])
        if (u.face >= 0 && mark[static_cast<std::size_t>(u.face)] == in_set) {
          mark[static_cast<std::size_t>(u.face)] = seen;
          part.push_back(u.face);
        }
    parts.push_back(std::move(part));
  }
  return parts;
}

}  // namespace

bool LeastSquaresConformalMap(const mesh::TriangleMesh& mesh,
                              const std::function<Corners(int face)>& corners_texels,
                              const std::vector<int>& faces, double t, std::vector<Corners>* uv) {
  std::unordered_map<int, int> local;
  std::vector<int> vertex_of_local;
  for (const int f : faces)
    for (const int v : mesh.faces[static_cast<std::size_t>(f)])
      if (local.emplace(v, static_cast<int>(vertex_of_local.size())).second)
        vertex_of_local.push_back(v);
  const int n = static_cast<int>(vertex_of_local.size());
  // Pins: the vertex farthest from the first, and the one farthest from it.
  auto point = [&](int l) {
    return mesh.vertices[static_cast<std::size_t>(vertex_of_local[static_cast<std::size_t>(l)])];
  };
  auto farthest_from = [&](int l0) {
    int best = l0;
    double d_best = -1;
    for (int l = 0; l < n; ++l) {
      const double d = (point(l) - point(l0)).squaredNorm();
      if (d > d_best) d_best = d, best = l;
    }
    return best;
  };
  const int pin_a = farthest_from(0);
  const int pin_b = farthest_from(pin_a);
  if (pin_a == pin_b) return false;
  const Eigen::Vector2d pin_a_uv(0.0, 0.0);
  const Eigen::Vector2d pin_b_uv((point(pin_b) - point(pin_a)).norm() / t, 0.0);
  // Unknowns: u then v of every free vertex.
  std::vector<int> column(static_cast<std::size_t>(n), -1);
  int num_free = 0;
  for (int l = 0; l < n; ++l)
    if (l != pin_a && l != pin_b) column[static_cast<std::size_t>(l)] = num_free++;
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<double> rhs;
  const int rows = 2 * static_cast<int>(faces.size());
  rhs.assign(static_cast<std::size_t>(rows), 0.0);
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const int f = faces[i];
    const Corners c = corners_texels(f);
    const double twice_area = Cross(c[1] - c[0], c[2] - c[0]);
    if (!(twice_area > 1e-12)) continue;  // degenerate: no conformal constraint
    const double s = std::sqrt(0.5 * twice_area);
    const int r1 = 2 * static_cast<int>(i), r2 = r1 + 1;
    for (std::size_t k = 0; k < 3; ++k) {
      // grad phi_k = R90(e_k) / (2A), e_k the edge opposite corner k (counter-clockwise).
      const Eigen::Vector2d e = c[(k + 2) % 3] - c[(k + 1) % 3];
      const double gx = -e.y() / twice_area, gy = e.x() / twice_area;
      const int l = local.at(mesh.faces[static_cast<std::size_t>(f)][k]);
      // r1 = s (u_x - v_y), r2 = s (u_y + v_x).
      const double cu1 = s * gx, cv1 = -s * gy, cu2 = s * gy, cv2 = s * gx;
      const int col = column[static_cast<std::size_t>(l)];
      if (col >= 0) {
        entries.emplace_back(r1, col, cu1);
        entries.emplace_back(r1, num_free + col, cv1);
        entries.emplace_back(r2, col, cu2);
        entries.emplace_back(r2, num_free + col, cv2);
      } else {
        const Eigen::Vector2d& p = l == pin_a ? pin_a_uv : pin_b_uv;
        rhs[static_cast<std::size_t>(r1)] -= cu1 * p.x() + cv1 * p.y();
        rhs[static_cast<std::size_t>(r2)] -= cu2 * p.x() + cv2 * p.y();
      }
    }
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2 * num_free);
  if (num_free > 0) {
    Eigen::SparseMatrix<double> a(rows, 2 * num_free);
    a.setFromTriplets(entries.begin(), entries.end());
    const Eigen::Map<const Eigen::VectorXd> b(rhs.data(), rows);
    const Eigen::SparseMatrix<double> normal = a.transpose() * a;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success) return false;
    x = solver.solve(a.transpose() * b);
    if (solver.info() != Eigen::Success || !x.allFinite()) return false;
  }
  uv->assign(faces.size(), Corners{});
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      const int l = local.at(mesh.faces[static_cast<std::size_t>(faces[i])][k]);
      const int col = column[static_cast<std::size_t>(l)];
      (*uv)[i][k] = col >= 0 ? Eigen::Vector2d(x[col], x[num_free + col])
                             : (l == pin_a ? pin_a_uv : pin_b_uv);
    }
  return true;
}

namespace {

// Throws OptionError unless lo < v <= hi (open_low) or lo <= v <= hi.
void RequireIn(double v, double lo, double hi, bool open_low, const char* what) {
  const bool ok = (open_low ? v > lo : v >= lo) && v <= hi;
  if (!ok)
    throw OptionError(std::string(what) + " must be in " + (open_low ? "(" : "[") +
                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

constexpr double kLarge = 1e9;

}  // namespace

void RigidChartOptions::Check() const {
  RequireIn(texel_size, 0.0, kLarge, true, "chart texel size");
  RequireIn(max_extent_texels, 1.0, kLarge, false, "largest chart side (texels)");
  RequireIn(max_normal_angle_deg, 0.0, 180.0, true, "chart normal angle (degrees)");
  if (gutter < 0) throw OptionError("chart gutter must be >= 0 texels");
}

void ConformalChartOptions::Check() const {
  RequireIn(texel_size, 0.0, kLarge, true, "chart texel size");
  RequireIn(max_side_texels, 0.0, kLarge, true, "conformal chart side (texels)");
  RequireIn(max_normal_angle_deg, 0.0, 180.0, true, "chart normal angle (degrees)");
  RequireIn(max_stretch, 1.0, kLarge, true, "chart stretch");
  RequireIn(max_extent_texels, 0.0, kLarge, true, "largest chart side (texels)");
}

void StripChartOptions::Check() const {
  RequireIn(texel_size, 0.0, kLarge, true, "chart texel size");
  RequireIn(max_stretch, 1.0, kLarge, true, "chart stretch");
  RequireIn(max_length_texels, 0.0, kLarge, true, "longest strip (texels)");
  RequireIn(max_normal_angle_deg, 0.0, 180.0, true, "chart normal angle (degrees)");
  if (min_fan_faces != 0 && min_fan_faces < 3)
    throw OptionError("fans need at least 3 faces (or 0: no fans)");
  RequireIn(max_stack_texels, 0.0, kLarge, false, "stack height (texels)");
  RequireIn(min_stack_cover, 0.0, 1.0, true, "stack cover");
  if (std::isnan(max_stack_overhang_texels))
    throw OptionError("stack overhang must be a number (< 0: no limit)");
  if (gutter < 0) throw OptionError("chart gutter must be >= 0 texels");
}

std::vector<std::vector<ChartFace>> MakeRigidCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    const RigidChartOptions& options) {
  options.Check();
  const std::size_t num_faces = mesh.faces.size();
  TEXLUME_CHECK(patches.size() == num_faces && unfoldings.size() == num_faces,
                "charts need one patch and one unfolding per face");
  const double t = options.texel_size;
  const int gutter = options.gutter;
  std::vector<std::vector<ChartFace>> charts;
  const std::vector<std::vector<int>> faces_of_vertex = FacesOfVertex(mesh);
  auto shares_vertex = [&](int a, int b) {
    for (int v : mesh.faces[static_cast<std::size_t>(a)])
      for (int g : faces_of_vertex[static_cast<std::size_t>(v)])
        if (g == b) return true;
    return false;
  };
  std::vector<int> chart_of(num_faces, -1);
  const double max_extent = options.max_extent_texels * t;
  const double min_cos = std::cos(options.max_normal_angle_deg * kPi / 180.0);
  // Seeds in breadth-first order over face adjacency, so each new chart starts
  // at the border of the charted region and few fragments are left between.
  const std::vector<int> seed_order = SeedOrder(mesh, unfoldings);
  for (const int seed_face : seed_order) {
    const auto seed = static_cast<std::size_t>(seed_face);
    if (chart_of[seed] >= 0) continue;
    const int chart_id = static_cast<int>(charts.size());
    std::vector<ChartFace> chart;
    std::unordered_map<std::int64_t, int> texels;  // chart texel -> face
    Eigen::Vector2d lo(0, 0), hi(0, 0), seed_extent(0, 0);
    bool first = true;
    auto corners_of = [&](const ChartFace& cf) {
      std::array<Eigen::Vector2d, 3> c;
      for (int k = 0; k < 3; ++k)
        c[static_cast<std::size_t>(k)] =
            cf.linear * patches[static_cast<std::size_t>(cf.face)]
                            .corners_in_frame[static_cast<std::size_t>(k)] +
            cf.translation;
      return c;
    };
    // Accepts a placement when it overlaps nothing, keeps clear of faces it does
    // not touch on the mesh, and the chart still fits an atlas.
    // Whether the chart's faces cover the way from p (inside a face the new
    // face does not touch on the mesh) to the nearest point of the new face:
    // then the two are near on the surface too, joined by the faces between
    // (a run of slivers), and filtering across may read one from the other.
    // An uncovered texel on the way is a crack, where their gutters would meet.
    auto covered_path = [&](const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p) {
      Eigen::Vector2d nearest = c[0];
      double best = std::numeric_limits<double>::max();
      for (std::size_t k = 0; k < 3; ++k) {
        const Eigen::Vector2d a = c[k], ab = c[(k + 1) % 3] - a;
        const double s = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
        const Eigen::Vector2d q = a + s * ab;
        if ((q - p).squaredNorm() < best) best = (q - p).squaredNorm(), nearest = q;
      }
      const double length = std::sqrt(best);
      const int steps = static_cast<int>(std::ceil(2.0 * length / t));
      for (int i = 1; i < steps; ++i) {
        const Eigen::Vector2d q = p + (nearest - p) * (static_cast<double>(i) / steps);
        const int qx = static_cast<int>(std::floor(q.x() / t));
        const int qy = static_cast<int>(std::floor(q.y() / t));
        if (mesh::SignedDistanceToTriangle(c, Eigen::Vector2d((qx + 0.5) * t, (qy + 0.5) * t)) <=
            0.0)
          continue;
        if (!texels.count(Key(qx, qy))) return false;
      }
      return true;
    };
    auto try_add = [&](const ChartFace& cf) {
      const auto c = corners_of(cf);
      Eigen::Vector2d clo = c[0], chi = c[0];
      for (const auto& p : c) clo = clo.cwiseMin(p), chi = chi.cwiseMax(p);
      if (!first) {
        // Within the extent, or the seed's own box (and a texel) when that is
        // larger: a sliver longer than the extent still gathers its neighbours.
        const Eigen::Vector2d nlo = lo.cwiseMin(clo), nhi = hi.cwiseMax(chi);
        if (((nhi - nlo).array() > seed_extent.array().max(max_extent)).any()) return false;
      }
      const double clearance = (2 * gutter + 1) * t;
      const int x0 = static_cast<int>(std::floor((clo.x() - clearance) / t));
      const int x1 = static_cast<int>(std::ceil((chi.x() + clearance) / t));
      const int y0 = static_cast<int>(std::floor((clo.y() - clearance) / t));
      const int y1 = static_cast<int>(std::ceil((chi.y() + clearance) / t));
      std::vector<std::int64_t> mine;
      for (int y = y0; y <= y1; ++y) {
        const auto [x_lo, x_hi] = mesh::TriangleRowSpan(c, (y + 0.5) * t, clearance);
        if (x_lo > x_hi) continue;
        for (int x = std::max(x0, static_cast<int>(std::floor(x_lo / t)));
             x <= std::min(x1, static_cast<int>(std::floor(x_hi / t))); ++x) {
          const Eigen::Vector2d p((x + 0.5) * t, (y + 0.5) * t);
          const double d = mesh::SignedDistanceToTriangle(c, p);
          if (d > clearance) continue;
          const auto it = texels.find(Key(x, y));
          if (it != texels.end()) {
            if (d < -0.5 * t) return false;  // overlap
            if (!shares_vertex(cf.face, it->second) && (d <= 0.0 || !covered_path(c, p)))
              return false;  // too close across a crack
          }
          if (d <= 0.0) mine.push_back(Key(x, y));
        }
      }
      for (const std::int64_t k : mine) texels.emplace(k, cf.face);
      if (first) seed_extent = (chi - clo).array() + t;  // and a texel of rounding
      lo = first ? clo : lo.cwiseMin(clo);
      hi = first ? chi : hi.cwiseMax(chi);
      first = false;
      chart.push_back(cf);
      chart_of[static_cast<std::size_t>(cf.face)] = chart_id;
      return true;
    };
    try_add({static_cast<int>(seed), Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero()});
    // Breadth-first over the mesh edges, each neighbour unfolded across the edge.
    std::deque<std::size_t> queue = {0};
    while (!queue.empty()) {
      const ChartFace from = chart[queue.front()];
      queue.pop_front();
      for (int k = 0; k < 3; ++k) {
        const synth::Unfolding& u =
            unfoldings[static_cast<std::size_t>(from.face)][static_cast<std::size_t>(k)];
        if (u.face < 0 || chart_of[static_cast<std::size_t>(u.face)] >= 0) continue;
        if (patches[static_cast<std::size_t>(u.face)].frame.z_axis.dot(patches[seed].frame.z_axis) <
            min_cos)
          continue;
        // p_from = R_u^T (p_nb - t_u), so chart = R_from R_u^T p_nb + ...
        ChartFace cf;
        cf.face = u.face;
        cf.linear = from.linear * u.rotation.transpose();
        cf.translation = from.translation - cf.linear * u.translation;
        if (try_add(cf)) queue.push_back(chart.size() - 1);
      }
    }
    charts.push_back(std::move(chart));
  }
  return charts;
}

Eigen::Vector2d SingularValues2(const Eigen::Matrix2d& m) {
  // For m = [a b; c d]: s1,2 = (sqrt((a+d)^2 + (c-b)^2) +- sqrt((a-d)^2 + (b+c)^2)) / 2.
  const double p = std::hypot(m(0, 0) + m(1, 1), m(1, 0) - m(0, 1));
  const double q = std::hypot(m(0, 0) - m(1, 1), m(0, 1) + m(1, 0));
  return {0.5 * (p + q), 0.5 * std::abs(p - q)};
}

std::vector<std::vector<ChartFace>> MakeConformalCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    const ConformalChartOptions& options, ConformalChartStats* stats) {
  const std::size_t num_faces = mesh.faces.size();
  TEXLUME_CHECK(patches.size() == num_faces && unfoldings.size() == num_faces,
                "charts need one patch and one unfolding per face");
  options.Check();
  const double t = options.texel_size;
  ConformalChartStats local_stats;
  ConformalChartStats& st = stats ? *stats : local_stats;

  // 1. Growth: from seeds in breadth-first order (each new chart starts at the
  // border of the charted region), faces join by their centroid's square
  // (L-infinity) distance from the seed's on the seed's tangent plane, nearest first.
  std::vector<Eigen::Vector3d> centroid(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f)
    centroid[f] = (mesh.Corner(f, 0) + mesh.Corner(f, 1) + mesh.Corner(f, 2)) / 3.0;
  const std::vector<int> seed_order = SeedOrder(mesh, unfoldings);
  const double half_side = 0.5 * options.max_side_texels * t;
  const double min_cos = std::cos(options.max_normal_angle_deg * kPi / 180.0);
  std::vector<int> chart_of(num_faces, -1);
  std::deque<std::vector<int>> work;
  for (const int seed : seed_order) {
    if (chart_of[static_cast<std::size_t>(seed)] != -1) continue;
    const int id = st.grown++;
    const mesh::TriangleFrame& frame = patches[static_cast<std::size_t>(seed)].frame;
    const Eigen::Vector3d& origin = centroid[static_cast<std::size_t>(seed)];
    auto distance = [&](int f) {
      const Eigen::Vector3d d = centroid[static_cast<std::size_t>(f)] - origin;
      return std::max(std::abs(d.dot(frame.x_axis)), std::abs(d.dot(frame.y_axis)));
    };
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> front;
    std::vector<int> faces;
    front.emplace(0.0, seed);
    chart_of[static_cast<std::size_t>(seed)] = id;
    while (!front.empty()) {
      const int f = front.top().second;
      front.pop();
      faces.push_back(f);
      for (const synth::Unfolding& u : unfoldings[static_cast<std::size_t>(f)]) {
        if (u.face < 0 || chart_of[static_cast<std::size_t>(u.face)] != -1) continue;
        if (patches[static_cast<std::size_t>(u.face)].frame.z_axis.dot(frame.z_axis) < min_cos)
          continue;
        const double d = distance(u.face);
        if (d > half_side) continue;
        chart_of[static_cast<std::size_t>(u.face)] = id;
        front.emplace(d, u.face);
      }
    }
    work.push_back(std::move(faces));
  }

  // 2. Flattening; a chart that fails is split across its longer side.
  std::vector<std::vector<ChartFace>> charts;
  std::vector<int> mark(num_faces, 0);
  int stamp = 0;
  while (!work.empty()) {
    std::vector<int> faces = std::move(work.front());
    work.pop_front();
    std::vector<Corners> uv;
    if (faces.size() == 1 ||
        (LeastSquaresConformalMap(
             mesh,
             [&](int f) { return FrameCornersTexels(patches[static_cast<std::size_t>(f)], t); },
             faces, t, &uv) &&
         ScaleAndCheck(patches, faces, t, options, uv))) {
      std::vector<ChartFace> chart;
      for (std::size_t i = 0; i < faces.size(); ++i) {
        const Corners c = FrameCornersTexels(patches[static_cast<std::size_t>(faces[i])], t);
        ChartFace cf;
        if (faces.size() == 1) {
          cf.face = faces[i];  // rigid: the frame itself
        } else {
          cf = AffineBetween(faces[i], c, uv[i]);
          cf.translation *= t;  // texels -> world units (linear is unitless)
        }
        chart.push_back(cf);
      }
      charts.push_back(std::move(chart));
      continue;
    }
    ++st.splits;
    // Split at the median of the centroids along the longer side of the
    // flattening (or, when it failed, of the 3D box).
    std::vector<double> key(faces.size());
    if (uv.size() == faces.size()) {
      Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max()), hi = -lo;
      for (const Corners& q : uv)
        for (const auto& p : q) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      const int axis = (hi - lo).x() >= (hi - lo).y() ? 0 : 1;
      for (std::size_t i = 0; i < faces.size(); ++i)
        key[i] = (uv[i][0] + uv[i][1] + uv[i][2])[axis];
    } else {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
      for (const int f : faces)
        lo = lo.cwiseMin(centroid[static_cast<std::size_t>(f)]),
        hi = hi.cwiseMax(centroid[static_cast<std::size_t>(f)]);
      Eigen::Index axis;
      (hi - lo).maxCoeff(&axis);
      for (std::size_t i = 0; i < faces.size(); ++i)
        key[i] = centroid[static_cast<std::size_t>(faces[i])][axis];
    }
    std::vector<std::size_t> order(faces.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
    std::vector<int> low, high;
    for (std::size_t i = 0; i < order.size(); ++i)
      (i < order.size() / 2 ? low : high).push_back(faces[order[i]]);
    for (const auto* half : {&low, &high})
      for (auto& part : ConnectedParts(*half, unfoldings, mark, stamp))
        work.push_back(std::move(part));
  }
  return charts;
}

}  // namespace texlume::atlas
