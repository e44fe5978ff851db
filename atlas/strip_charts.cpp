#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>
#include <limits>
#include <optional>
#include <queue>
#include <set>
#include <tuple>
#include <unordered_map>

#include "core/check.h"
#include "core/errors.h"
#include "atlas/chart_parts.h"
#include "atlas/charts.h"
#include "mesh/triangle_frame.h"

namespace texlume::atlas {
using namespace chart_parts;

namespace {

/// One end of a strip being grown towards +x: the rung (the edge that crosses
/// the band) from its top vertex to its bottom vertex, in band texels, and the
/// strip's face on its -x side.
struct Rung {
  int face = -1;
  int top = -1, bottom = -1;  ///< mesh vertices
  Eigen::Vector2d top_xy, bottom_xy;
};

/// The image of `p` under the similarity (rotation, uniform scale and
/// translation) taking `from_a` to `to_a` and `from_b` to `to_b`, as complex
/// numbers: to_a + (to_b - to_a) / (from_b - from_a) (p - from_a). from_a != from_b.
Eigen::Vector2d MapBySimilarity(const Eigen::Vector2d& from_a, const Eigen::Vector2d& from_b,
                                const Eigen::Vector2d& to_a, const Eigen::Vector2d& to_b,
                                const Eigen::Vector2d& p) {
  using Complex = std::complex<double>;
  const Eigen::Vector2d from = from_b - from_a, to = to_b - to_a, d = p - from_a;
  const Complex z = Complex(to.x(), to.y()) / Complex(from.x(), from.y());
  const Complex q = Complex(to_a.x(), to_a.y()) + z * Complex(d.x(), d.y());
  return {q.real(), q.imag()};
}

/// The texel stretch of the map taking `from` onto `to`: its larger singular
/// value or the inverse of its smaller, whichever is larger (infinite when `to`
/// is degenerate or flipped).
double StretchOf(const Corners& from, const Corners& to) {
  if (!(Cross(to[1] - to[0], to[2] - to[0]) > 1e-6)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d sigma = SingularValues2(AffineBetween(-1, from, to).linear);
  return std::max(sigma.x(), 1.0 / sigma.y());
}

/// Where on the line y = `y_line`, beyond `x_min`, corner `k` of `to` goes so
/// that the map from `from` stretches least: a scan over three times the
/// face's longest side, then a ternary search around the best sample. Returns
/// (x, stretch).
std::pair<double, double> LeastStretchOnLine(const Corners& from, Corners to, std::size_t k,
                                             double y_line, double x_min) {
  double longest = 0.0;
  for (std::size_t a = 0; a < 3; ++a)
    longest = std::max(longest, (from[a] - from[(a + 1) % 3]).norm());
  auto stretch = [&](double x) {
    to[k] = Eigen::Vector2d(x, y_line);
    return StretchOf(from, to);
  };
  constexpr int kSamples = 64;
  const double step = 3.0 * longest / kSamples;
  double best_x = x_min, best = stretch(x_min);
  for (int i = 1; i <= kSamples; ++i)
    if (const double s = stretch(x_min + i * step); s < best) best = s, best_x = x_min + i * step;
  double a = std::max(x_min, best_x - step), b = best_x + step;
  for (int i = 0; i < 40; ++i) {
    const double m1 = a + (b - a) / 3.0, m2 = b - (b - a) / 3.0;
    if (stretch(m1) < stretch(m2))
      b = m2;
    else
      a = m1;
  }
  const double x = 0.5 * (a + b);
  const double s = stretch(x);
  return s < best ? std::make_pair(x, s) : std::make_pair(best_x, best);
}

int CornerOf(const mesh::TriangleMesh& mesh, int face, int vertex) {
  for (int k = 0; k < 3; ++k)
    if (mesh.faces[static_cast<std::size_t>(face)][static_cast<std::size_t>(k)] == vertex) return k;
  return -1;
}

/// The face across edge (a, b) of `face`, or -1.
int FaceAcross(const mesh::TriangleMesh& mesh,
               const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, int face, int a, int b) {
  const auto& v = mesh.faces[static_cast<std::size_t>(face)];
  for (std::size_t k = 0; k < 3; ++k) {
    const int p = v[k], q = v[(k + 1) % 3];
    if ((p == a && q == b) || (p == b && q == a))
      return unfoldings[static_cast<std::size_t>(face)][k].face;
  }
  return -1;
}

/// The band's 180-degree turn about its centre line: maps a strip growing
/// towards -x onto one growing towards +x, keeping the orientation. Corners
/// are on the band's lines and stay exactly on them.
Eigen::Vector2d TurnBand(const Eigen::Vector2d& q, double y_bottom, double y_top) {
  return {-q.x(), std::abs(q.y() - y_bottom) < std::abs(q.y() - y_top) ? y_top : y_bottom};
}

/// The face after `f` around its corner at `v`, counter-clockwise (across the
/// edge from the corner after next to `v`) or clockwise (across the edge from
/// `v` to the next corner); -1 at the border.
int FanNeighbour(const mesh::TriangleMesh& mesh,
                 const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, int f, int v,
                 bool counter_clockwise) {
  const int k = CornerOf(mesh, f, v);
  if (k < 0) return -1;
  const auto edge = static_cast<std::size_t>(counter_clockwise ? (k + 2) % 3 : k);
  return unfoldings[static_cast<std::size_t>(f)][edge].face;
}

/// The faces `in_fan` marks around `v`, as runs in counter-clockwise order:
/// each run starts where its clockwise neighbour is not in the fan; a closed
/// ring starts at its lowest face.
std::vector<std::vector<int>> FanRuns(const mesh::TriangleMesh& mesh,
                                      const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                                      int v, const std::vector<int>& faces,
                                      const std::vector<char>& in_fan) {
  std::set<int> left;
  for (const int f : faces)
    if (in_fan[static_cast<std::size_t>(f)]) left.insert(f);
  std::vector<std::vector<int>> runs;
  auto walk = [&](int f) {
    std::vector<int> run;
    while (f >= 0 && left.erase(f)) {
      run.push_back(f);
      f = FanNeighbour(mesh, unfoldings, f, v, true);
    }
    runs.push_back(std::move(run));
  };
  for (const int f : faces) {
    if (!left.count(f)) continue;
    const int before = FanNeighbour(mesh, unfoldings, f, v, false);
    if (before < 0 || !in_fan[static_cast<std::size_t>(before)]) walk(f);
  }
  while (!left.empty()) walk(*left.begin());
  return runs;
}

/// A run of faces around `v` (counter-clockwise) unfolded rigidly about `v`
/// and cut into sectors, each turned so its bisector is upright with `v` at
/// (0, y_bottom): per sector its faces' corners in band texels. When the run is
/// flat, each sector also takes the free faces beyond it in the same plane
/// (a cap subdivided into rings) whose centroids lie within its angles. The
/// number of sectors minimises the row area they need when upright and turned
/// sectors alternate, about n (R^2 tan(beta / 2) + 2 g R / cos(beta / 2)) for
/// n sectors of angle beta, radius R and gutter g, with beta at most 90
/// degrees. Empty when the run is shorter than 3 faces or wider than `max_length`.
std::vector<std::vector<std::pair<int, Corners>>> FanSectors(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, const std::vector<char>& used, int v,
    const std::vector<int>& run, double t, int gutter, double max_length, double y_bottom) {
  constexpr double kMaxSectorAngle = 0.5 * kPi;
  const double flat_cos = std::cos(0.25 * kPi / 180.0);  // coplanar faces
  std::vector<Corners> unfolded;
  // The angle about v of each face's first edge, then of the last face's second.
  std::vector<double> phi = {0.0};
  double radius = 0.0;
  int previous_last = -1;  // the previous face's second edge's far vertex
  for (const int f : run) {
    const int k = CornerOf(mesh, f, v);
    const auto ks = static_cast<std::size_t>(k), a = (ks + 1) % 3, b = (ks + 2) % 3;
    const auto& fv = mesh.faces[static_cast<std::size_t>(f)];
    if (previous_last >= 0 && fv[a] != previous_last) break;  // orientation flips: run ends
    const Corners c = FrameCornersTexels(patches[static_cast<std::size_t>(f)], t);
    const Eigen::Vector2d ea = c[a] - c[ks], eb = c[b] - c[ks];
    const double theta = std::atan2(Cross(ea, eb), ea.dot(eb));
    if (!(theta > 1e-9) || !(ea.norm() > 0.0)) break;
    const Eigen::Matrix2d turn =
        Eigen::Rotation2Dd(phi.back() - std::atan2(ea.y(), ea.x())).toRotationMatrix();
    Corners q;
    q[ks] = Eigen::Vector2d::Zero();
    q[b] = turn * eb;
    if (unfolded.empty()) {
      q[a] = turn * ea;
    } else {  // the shared edge exactly where the previous face put it
      const int pk = CornerOf(mesh, run[unfolded.size() - 1], v);
      q[a] = unfolded.back()[static_cast<std::size_t>((pk + 2) % 3)];
    }
    unfolded.push_back(q);
    phi.push_back(phi.back() + theta);
    radius = std::max({radius, ea.norm(), eb.norm()});
    previous_last = fv[b];
  }
  const std::size_t m = unfolded.size();
  if (m < 3) return {};
  const double total = phi.back();

  // A flat run takes in the free faces of its plane beyond it, reached across
  // edges, whose centroids lie within its angles (the plane's coordinates: x
  // along the first face's first edge, counter-clockwise about the normal).
  const Eigen::Vector3d& normal = patches[static_cast<std::size_t>(run[0])].frame.z_axis;
  bool flat = true;
  for (std::size_t i = 0; i < m; ++i)
    flat = flat && patches[static_cast<std::size_t>(run[i])].frame.z_axis.dot(normal) >= flat_cos;
  std::vector<int> beyond;
  std::vector<Corners> beyond_q;
  std::vector<double> beyond_angle;
  if (flat) {
    const Eigen::Vector3d& centre = mesh.vertices[static_cast<std::size_t>(v)];
    const int first_a = mesh.faces[static_cast<std::size_t>(run[0])]
                                  [static_cast<std::size_t>((CornerOf(mesh, run[0], v) + 1) % 3)];
    Eigen::Vector3d e1 = mesh.vertices[static_cast<std::size_t>(first_a)] - centre;
    e1 = (e1 - e1.dot(normal) * normal).normalized();
    const Eigen::Vector3d e2 = normal.cross(e1);
    auto plane = [&](int w) -> Eigen::Vector2d {
      const Eigen::Vector3d d = mesh.vertices[static_cast<std::size_t>(w)] - centre;
      return Eigen::Vector2d(d.dot(e1), d.dot(e2)) / t;
    };
    std::set<int> taken(run.begin(), run.begin() + static_cast<std::ptrdiff_t>(m));
    std::deque<int> queue(run.begin(), run.begin() + static_cast<std::ptrdiff_t>(m));
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      for (const synth::Unfolding& u : unfoldings[static_cast<std::size_t>(f)]) {
        const int g = u.face;
        if (g < 0 || used[static_cast<std::size_t>(g)] || taken.count(g) ||
            patches[static_cast<std::size_t>(g)].frame.z_axis.dot(normal) < flat_cos)
          continue;
        Corners q;
        for (std::size_t k = 0; k < 3; ++k)
          q[k] = plane(mesh.faces[static_cast<std::size_t>(g)][k]);
        const Eigen::Vector2d centroid = (q[0] + q[1] + q[2]) / 3.0;
        double angle = std::atan2(centroid.y(), centroid.x());
        if (angle < 0.0) angle += 2.0 * kPi;
        if (!(angle < total)) continue;
        taken.insert(g);
        queue.push_back(g);
        beyond.push_back(g);
        beyond_q.push_back(q);
        beyond_angle.push_back(angle);
        for (const auto& p : q) radius = std::max(radius, p.norm());
      }
    }
  }
  if (radius + 2.0 * gutter > max_length) return {};
  std::size_t sectors = 0;
  double best_cost = std::numeric_limits<double>::max();
  for (std::size_t n = 1; n <= m; ++n) {
    const double beta = total / static_cast<double>(n);
    if (beta > kMaxSectorAngle && n < m) continue;
    if (2.0 * radius * std::sin(0.5 * std::min(beta, kPi)) > max_length) continue;
    const double cost = static_cast<double>(n) * (radius * radius * std::tan(0.5 * beta) +
                                                  2.0 * gutter * radius / std::cos(0.5 * beta));
    if (beta < kPi && cost < best_cost) best_cost = cost, sectors = n;
  }
  if (sectors == 0) return {};
  // Cuts at the face edges nearest to equal angles.
  std::vector<std::size_t> cuts = {0};
  for (std::size_t j = 1; j < sectors; ++j) {
    const double target = total * static_cast<double>(j) / static_cast<double>(sectors);
    std::size_t best = cuts.back() + 1;
    for (std::size_t i = best; i <= m - (sectors - j); ++i)  // leave a face per sector after
      if (std::abs(phi[i] - target) < std::abs(phi[best] - target)) best = i;
    cuts.push_back(best);
  }
  cuts.push_back(m);
  std::vector<std::vector<std::pair<int, Corners>>> out;
  for (std::size_t s = 0; s + 1 < cuts.size(); ++s) {
    const double mid = 0.5 * (phi[cuts[s]] + phi[cuts[s + 1]]);
    const Eigen::Matrix2d upright = Eigen::Rotation2Dd(0.5 * kPi - mid).toRotationMatrix();
    std::vector<std::pair<int, Corners>> sector;
    std::set<int> in_sector;
    for (std::size_t i = cuts[s]; i < cuts[s + 1]; ++i) {
      sector.emplace_back(run[i], unfolded[i]);
      in_sector.insert(run[i]);
    }
    // The faces beyond within the sector's angles, reached from its own faces.
    for (bool grew = true; grew;) {
      grew = false;
      for (std::size_t j = 0; j < beyond.size(); ++j) {
        if (in_sector.count(beyond[j]) || beyond_angle[j] < phi[cuts[s]] ||
            beyond_angle[j] >= phi[cuts[s + 1]])
          continue;
        bool touches = false;
        for (const synth::Unfolding& u : unfoldings[static_cast<std::size_t>(beyond[j])])
          touches = touches || (u.face >= 0 && in_sector.count(u.face));
        if (!touches) continue;
        sector.emplace_back(beyond[j], beyond_q[j]);
        in_sector.insert(beyond[j]);
        grew = true;
      }
    }
    for (auto& [f, q] : sector)
      for (auto& p : q) p = upright * p + Eigen::Vector2d(0.0, y_bottom);
    out.push_back(std::move(sector));
  }
  return out;
}

}  // namespace

double PreferredBandHeight(const std::vector<synth::TrianglePatch>& patches, double texel_size) {
  if (patches.empty()) return 0.0;
  std::vector<double> tallest(patches.size(), 0.0);
  for (std::size_t f = 0; f < patches.size(); ++f) {
    const Corners c = FrameCornersTexels(patches[f], texel_size);
    const double twice_area = Cross(c[1] - c[0], c[2] - c[0]);
    for (std::size_t k = 0; k < 3; ++k) {
      const double length = (c[(k + 1) % 3] - c[k]).norm();
      if (length > 0.0) tallest[f] = std::max(tallest[f], twice_area / length);
    }
  }
  const auto middle = tallest.begin() + static_cast<std::ptrdiff_t>(tallest.size() / 2);
  std::nth_element(tallest.begin(), middle, tallest.end());
  return std::round(*middle);
}

std::vector<std::vector<ChartFace>> MakeStripCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, const StripChartOptions& options,
    StripChartStats* stats) {
  const std::size_t num_faces = mesh.faces.size();
  TEXLUME_CHECK(patches.size() == num_faces && unfoldings.size() == num_faces,
                "charts need one patch and one unfolding per face");
  options.Check();
  const double t = options.texel_size;
  StripChartStats local_stats;
  StripChartStats& st = stats ? *stats : local_stats;
  const double min_cos = std::cos(options.max_normal_angle_deg * kPi / 180.0);
  // Band lines a hair outside texel centres, so the centres on them are inside.
  constexpr double kInset = 1e-3;  // texels
  // A seed within this relative distance of the preferred height takes it
  // (within the stretch bound, which also has to absorb the other faces).
  const double snap_to_preferred = std::min(0.2, 0.8 * (options.max_stretch - 1.0));

  std::vector<char> used(num_faces, 0);
  std::vector<std::vector<ChartFace>> charts;
  // Seeds: the free face with the fewest free neighbours (so strips leave few
  // faces stranded), then the earliest in breadth-first order.
  const std::vector<int> bfs = SeedOrder(mesh, unfoldings);
  std::vector<int> rank(num_faces, 0), free_neighbours(num_faces, 0);
  for (std::size_t i = 0; i < bfs.size(); ++i)
    rank[static_cast<std::size_t>(bfs[i])] = static_cast<int>(i);
  std::set<std::tuple<int, int, int>> seeds;  // (free neighbours, rank, face)
  for (std::size_t f = 0; f < num_faces; ++f) {
    for (const synth::Unfolding& u : unfoldings[f]) free_neighbours[f] += u.face >= 0 ? 1 : 0;
    seeds.emplace(free_neighbours[f], rank[f], static_cast<int>(f));
  }
  auto mark_used = [&](int f) {
    const auto fs = static_cast<std::size_t>(f);
    used[fs] = 1;
    seeds.erase({free_neighbours[fs], rank[fs], f});
    for (const synth::Unfolding& u : unfoldings[fs]) {
      if (u.face < 0 || used[static_cast<std::size_t>(u.face)]) continue;
      const auto g = static_cast<std::size_t>(u.face);
      seeds.erase({free_neighbours[g], rank[g], u.face});
      --free_neighbours[g];
      seeds.emplace(free_neighbours[g], rank[g], u.face);
    }
  };
  // Undoes mark_used (faces freed in the reverse order they were used).
  auto unmark_used = [&](int f) {
    const auto fs = static_cast<std::size_t>(f);
    used[fs] = 0;
    int free = 0;
    for (const synth::Unfolding& u : unfoldings[fs]) {
      if (u.face < 0 || used[static_cast<std::size_t>(u.face)]) continue;
      const auto g = static_cast<std::size_t>(u.face);
      seeds.erase({free_neighbours[g], rank[g], u.face});
      ++free_neighbours[g];
      seeds.emplace(free_neighbours[g], rank[g], u.face);
      ++free;
    }
    free_neighbours[fs] = free;
    seeds.emplace(free, rank[fs], f);
  };
  const double preferred_height = PreferredBandHeight(patches, t);
  // A band's height (whole texels) for a face of this height over its side edge.
  auto band_height_for = [&](double height) {
    if (std::abs(height / preferred_height - 1.0) < snap_to_preferred) return preferred_height;
    if (!options.fit_irregular_faces) return std::max(1.0, std::round(height));
    // Else the nearest height of the ladder preferred * s^k (s the stretch
    // bound): the face is stretched by at most sqrt(s) across the band, and the
    // bands of an irregular mesh share few heights, so they fill atlas rows.
    const double k =
        std::round(std::log(height / preferred_height) / std::log(options.max_stretch));
    return std::max(1.0, std::round(preferred_height * std::pow(options.max_stretch, k)));
  };
  // The face's map into the band when its stretch is within the bound.
  auto place = [&](int f, const Corners& band) -> std::optional<ChartFace> {
    const Corners c = FrameCornersTexels(patches[static_cast<std::size_t>(f)], t);
    const double twice_area = Cross(band[1] - band[0], band[2] - band[0]);
    if (!(twice_area > 1e-6) || !(Cross(c[1] - c[0], c[2] - c[0]) > 1e-12)) return std::nullopt;
    ChartFace cf = AffineBetween(f, c, band);
    const Eigen::Vector2d sigma = SingularValues2(cf.linear);
    if (!(sigma.x() <= options.max_stretch && sigma.y() >= 1.0 / options.max_stretch))
      return std::nullopt;
    return cf;
  };

  // 0. Fans: the free faces around a vertex of at least `min_fan_faces` faces
  // (cylinder caps, cone tips, the poles of latitude-longitude spheres) cannot
  // follow a band, since every face shares the centre. Each fan is unfolded
  // about its centre (rigid, stretch 1) and cut into sectors; a sector stands
  // in its band with the centre on the bottom line and its bisector upright, so
  // turned sectors nest between upright ones in an atlas row.
  if (options.min_fan_faces > 0) {
    const std::vector<std::vector<int>> faces_of_vertex = FacesOfVertex(mesh);
    std::vector<int> centres;
    for (std::size_t v = 0; v < faces_of_vertex.size(); ++v)
      if (static_cast<int>(faces_of_vertex[v].size()) >= options.min_fan_faces)
        centres.push_back(static_cast<int>(v));
    std::stable_sort(centres.begin(), centres.end(), [&](int a, int b) {
      return faces_of_vertex[static_cast<std::size_t>(a)].size() >
             faces_of_vertex[static_cast<std::size_t>(b)].size();
    });
    std::vector<char> in_fan(num_faces, 0);
    for (const int v : centres) {
      std::vector<int> free_faces;
      Eigen::Vector3d mean_normal = Eigen::Vector3d::Zero();
      for (const int f : faces_of_vertex[static_cast<std::size_t>(v)])
        if (!used[static_cast<std::size_t>(f)]) {
          free_faces.push_back(f);
          mean_normal += patches[static_cast<std::size_t>(f)].frame.z_axis;
        }
      if (static_cast<int>(free_faces.size()) < options.min_fan_faces || !(mean_normal.norm() > 0))
        continue;
      mean_normal.normalize();
      for (const int f : free_faces)
        in_fan[static_cast<std::size_t>(f)] =
            patches[static_cast<std::size_t>(f)].frame.z_axis.dot(mean_normal) >= min_cos;
      for (const std::vector<int>& run : FanRuns(mesh, unfoldings, v, free_faces, in_fan)) {
        const auto sectors = FanSectors(mesh, patches, unfoldings, used, v, run, t, options.gutter,
                                        options.max_length_texels, 0.5 - kInset);
        if (sectors.empty()) continue;  // too short or too large: left to strips
        ++st.fans;
        for (const auto& sector : sectors) {
          for (const auto& [f, q] : sector) mark_used(f);
          charts.push_back(ChartOfBand(patches, t, sector));
          ++st.fan_sectors;
        }
      }
      for (const int f : free_faces) in_fan[static_cast<std::size_t>(f)] = 0;
    }
  }

  while (!seeds.empty()) {
    const int seed = std::get<2>(*seeds.begin());
    const Corners c = FrameCornersTexels(patches[static_cast<std::size_t>(seed)], t);
    const Eigen::Vector3d& seed_normal = patches[static_cast<std::size_t>(seed)].frame.z_axis;
    const double twice_area = Cross(c[1] - c[0], c[2] - c[0]);
    // 1. The seed's side edge: one along the charted region or the mesh border
    // (so bands lie along each other), the tallest such.
    int side = -1;
    double side_height = 0.0;
    std::tuple<bool, double> side_key;
    for (int k = 0; k < 3; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      const double length = (c[(ks + 1) % 3] - c[ks]).norm();
      if (!(length > 0.0)) continue;
      const double height = twice_area / length;
      const int across = unfoldings[static_cast<std::size_t>(seed)][ks].face;
      const bool borders = across < 0 || used[static_cast<std::size_t>(across)];
      // Prefer: along the charted region, then the tallest (or the nearest the
      // preferred height).
      const double h_key = options.side == StripSide::kNearestPreferred
                               ? -std::abs(height - preferred_height)
                               : height;
      const auto key = std::make_tuple(borders, h_key);
      if (side < 0 || key > side_key) side = k, side_key = key, side_height = height;
    }
    const double band_height = band_height_for(side_height);
    // The band's lines; a stacked band moves them up (step 4).
    double y_bottom = 0.5 - kInset, y_top = 0.5 + band_height + kInset;
    std::optional<ChartFace> seed_placement;
    Corners seed_band;
    if (side >= 0) {
      const auto k0 = static_cast<std::size_t>(side), k1 = (k0 + 1) % 3, k2 = (k0 + 2) % 3;
      const Eigen::Vector2d along = (c[k1] - c[k0]).normalized();
      seed_band[k0] = Eigen::Vector2d(0.0, y_bottom);
      seed_band[k1] = Eigen::Vector2d((c[k1] - c[k0]).norm(), y_bottom);
      seed_band[k2] = Eigen::Vector2d((c[k2] - c[k0]).dot(along), y_top);
      seed_placement = place(seed, seed_band);
    }
    mark_used(seed);
    if (!seed_placement) {  // degenerate or too small for a band: on its own, rigid
      ++st.lone_faces;
      charts.push_back({ChartFace{seed, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero()}});
      continue;
    }
    ++st.strips;
    std::vector<std::pair<int, Corners>> band = {{seed, seed_band}};
    const double lo_x = std::min({seed_band[0].x(), seed_band[1].x(), seed_band[2].x()});
    double hi_x = std::max({seed_band[0].x(), seed_band[1].x(), seed_band[2].x()});

    // A stacked band's bottom line is the top line of the band under it: the
    // vertices of that band's top chain keep their x there, and no other
    // vertex may land on the line within the chain's span (step 4).
    std::unordered_map<int, double> anchor_x;
    double anchor_lo = 0.0, anchor_hi = 0.0;
    // A stacked band stays within `max_stack_overhang_texels` beyond the ends
    // of the chain it stands on, so stacks stay near rectangles.
    auto within_overhang = [&](double x) {
      return options.max_stack_overhang_texels < 0.0 ||
             (x >= anchor_lo - options.max_stack_overhang_texels &&
              x <= anchor_hi + options.max_stack_overhang_texels);
    };

    // In a stacked band, the x of face g's apex going onto the free line, by
    // the similarity of the next face across (apex, the rung's end on the band
    // below), whose edge on that band has both ends where the band put them; not
    // by the rung's, so the differences between the two lines' lengths (a torus
    // ring's circles) do not add up along the band. None when that face is used
    // or its third corner is not on the band below.
    auto free_line_x = [&](int g, int apex_vertex, const Rung& rung, bool turned,
                           bool apex_on_top) -> std::optional<double> {
      const int on_line = turned ? rung.top : rung.bottom;  // the rung's end on the band below
      const Eigen::Vector2d& on_line_xy = turned ? rung.top_xy : rung.bottom_xy;
      const int h = FaceAcross(mesh, unfoldings, g, apex_vertex, on_line);
      if (h < 0 || used[static_cast<std::size_t>(h)]) return std::nullopt;
      const int h_on_line = CornerOf(mesh, h, on_line), h_apex = CornerOf(mesh, h, apex_vertex);
      if (h_on_line < 0 || h_apex < 0) return std::nullopt;
      const auto hs = static_cast<std::size_t>(h);
      const auto h_next = static_cast<std::size_t>(3 - h_on_line - h_apex);
      const auto it = anchor_x.find(mesh.faces[hs][h_next]);
      if (it == anchor_x.end()) return std::nullopt;
      const double next_x = turned ? -it->second : it->second;
      if (!(next_x > on_line_xy.x() + 1e-3)) return std::nullopt;
      const Corners ph = FrameCornersTexels(patches[hs], t);
      const Eigen::Vector2d q = MapBySimilarity(ph[static_cast<std::size_t>(h_on_line)], ph[h_next],
                                                on_line_xy, Eigen::Vector2d(next_x, on_line_xy.y()),
                                                ph[static_cast<std::size_t>(h_apex)]);
      if ((q.y() > on_line_xy.y()) != apex_on_top) return std::nullopt;
      return q.x();
    };

    // 2. Growth towards +x across `rung` while faces fit; `lo` is the band's
    // far end in this direction's coordinates (`turned`: the band turned by
    // 180 degrees, growing towards -x). Returns the faces added.
    auto grow = [&](Rung rung, double lo, bool turned) {
      std::vector<std::pair<int, Corners>> added;
      double hi = -std::numeric_limits<double>::max();
      for (;;) {
        const int g = FaceAcross(mesh, unfoldings, rung.face, rung.top, rung.bottom);
        if (g < 0 || used[static_cast<std::size_t>(g)]) break;
        if (patches[static_cast<std::size_t>(g)].frame.z_axis.dot(seed_normal) < min_cos) break;
        const int k_top = CornerOf(mesh, g, rung.top), k_bottom = CornerOf(mesh, g, rung.bottom);
        if (k_top < 0 || k_bottom < 0) break;
        const int k_apex = 3 - k_top - k_bottom;
        const Corners p = FrameCornersTexels(patches[static_cast<std::size_t>(g)], t);
        // The similarity taking the rung's frame points onto its band points.
        if (p[k_top] == p[k_bottom]) break;
        const Eigen::Vector2d apex_mapped =
            MapBySimilarity(p[k_bottom], p[k_top], rung.bottom_xy, rung.top_xy, p[k_apex]);
        // The apex goes to the nearer band line and must lie beyond the rung's
        // end on that line (bands are monotone, so faces never overlap).
        bool apex_on_top = apex_mapped.y() > 0.5 * (y_bottom + y_top);
        Eigen::Vector2d apex(apex_mapped.x(), apex_on_top ? y_top : y_bottom);
        const int apex_vertex =
            mesh.faces[static_cast<std::size_t>(g)][static_cast<std::size_t>(k_apex)];
        if (!anchor_x.empty() && apex_on_top != turned)
          if (const auto x = free_line_x(g, apex_vertex, rung, turned, apex_on_top)) apex.x() = *x;
        if (!anchor_x.empty() && !within_overhang(turned ? -apex.x() : apex.x())) break;
        if (!anchor_x.empty() && apex_on_top == turned) {  // onto the band below
          const auto it = anchor_x.find(apex_vertex);
          const double x = turned ? -apex.x() : apex.x();
          if (it != anchor_x.end())
            apex.x() = turned ? -it->second : it->second;
          else if (x > anchor_lo - 1.0 && x < anchor_hi + 1.0)
            break;
        }
        if (apex.x() <= (apex_on_top ? rung.top_xy.x() : rung.bottom_xy.x()) + 1e-3) break;
        if (std::max(hi, apex.x()) - lo > options.max_length_texels) break;
        Corners q;
        q[static_cast<std::size_t>(k_top)] = rung.top_xy;
        q[static_cast<std::size_t>(k_bottom)] = rung.bottom_xy;
        q[static_cast<std::size_t>(k_apex)] = apex;
        bool fits = place(g, q).has_value();
        if (!fits && options.fit_irregular_faces && anchor_x.empty()) {
          // An irregular face the rung's similarity stretches too far: its apex
          // at the least-stretching place on either line instead.
          const auto ka = static_cast<std::size_t>(k_apex);
          double least = std::numeric_limits<double>::infinity();
          for (const bool on_top : {apex_on_top, !apex_on_top}) {
            const double x_min = (on_top ? rung.top_xy.x() : rung.bottom_xy.x()) + 1e-3;
            const auto [x, s] = LeastStretchOnLine(p, q, ka, on_top ? y_top : y_bottom, x_min);
            if (s < least) least = s, apex = Eigen::Vector2d(x, on_top ? y_top : y_bottom);
          }
          apex_on_top = apex.y() == y_top;
          q[ka] = apex;
          if (std::max(hi, apex.x()) - lo > options.max_length_texels) break;
          fits = place(g, q).has_value();
        }
        if (!fits) break;
        mark_used(g);
        added.emplace_back(g, q);
        hi = std::max({hi, rung.top_xy.x(), rung.bottom_xy.x(), apex.x()});
        rung.face = g;
        if (apex_on_top) {
          rung.top = apex_vertex;
          rung.top_xy = apex;
        } else {
          rung.bottom = apex_vertex;
          rung.bottom_xy = apex;
        }
      }
      return std::make_pair(added, hi);
    };
    const auto k0 = static_cast<std::size_t>(side), k1 = (k0 + 1) % 3, k2 = (k0 + 2) % 3;
    const auto& sv = mesh.faces[static_cast<std::size_t>(seed)];
    // Towards +x across (apex, v1).
    Rung right{seed, sv[k2], sv[k1], seed_band[k2], seed_band[k1]};
    auto [to_right, right_hi] = grow(right, lo_x, false);
    for (auto& fq : to_right) band.push_back(fq);
    if (!to_right.empty()) hi_x = std::max(hi_x, right_hi);
    // Towards -x across (v0, apex), grown in the band turned by 180 degrees.
    Rung left{seed, sv[k0], sv[k2], TurnBand(seed_band[k0], y_bottom, y_top),
              TurnBand(seed_band[k2], y_bottom, y_top)};
    auto to_left = grow(left, -hi_x, true).first;
    for (auto& [f, q] : to_left) {
      for (auto& p : q) p = TurnBand(p, y_bottom, y_top);
      band.emplace_back(f, q);
    }
    // 3. Square ends: each end rung is made to cross the band straight (its
    // two ends moved to their mean, or one onto the other) when the faces on it
    // stay within the stretch bound, so bands abut in atlas rows.
    for (const bool right_end : {true, false}) {
      auto outer = [&](double y_line) {
        double x =
            right_end ? -std::numeric_limits<double>::max() : std::numeric_limits<double>::max();
        for (const auto& fq : band)
          for (const auto& p : fq.second)
            if (p.y() == y_line) x = right_end ? std::max(x, p.x()) : std::min(x, p.x());
        return x;
      };
      const double x_top = outer(y_top), x_bottom = outer(y_bottom);
      for (const double x : {0.5 * (x_top + x_bottom), x_top, x_bottom}) {
        auto moved = band;
        bool ok = true;
        for (auto& [f, q] : moved) {
          bool touched = false;
          for (auto& p : q)
            if ((p.y() == y_top && p.x() == x_top) || (p.y() == y_bottom && p.x() == x_bottom)) {
              p.x() = x;
              touched = true;
            }
          if (touched && !place(f, q)) ok = false;
        }
        if (ok) {
          band = std::move(moved);
          break;
        }
      }
    }
    // 4. Stacking: a band grown on the top line of the last one, from a free
    // face across one of its top edges, shares that line (no gutter rows
    // between them). It is kept when it covers most of the band below and the
    // stack stays within `max_stack_texels`; else its faces are freed.
    std::vector<std::pair<int, Corners>> below = band;
    double stack_height = band_height;
    while (options.max_stack_texels > 0.0) {
      anchor_x.clear();
      anchor_lo = std::numeric_limits<double>::max();
      anchor_hi = -anchor_lo;
      for (const auto& [f, q] : below)
        for (std::size_t k = 0; k < 3; ++k)
          if (q[k].y() == y_top) {
            anchor_x[mesh.faces[static_cast<std::size_t>(f)][k]] = q[k].x();
            anchor_lo = std::min(anchor_lo, q[k].x());
            anchor_hi = std::max(anchor_hi, q[k].x());
          }
      // The seed: across the top edge nearest the middle of the chain.
      int next = -1;
      std::size_t next_k0 = 0;
      double next_key = std::numeric_limits<double>::max();
      for (const auto& [f, q] : below) {
        const auto& fv = mesh.faces[static_cast<std::size_t>(f)];
        for (std::size_t k = 0; k < 3; ++k) {
          const std::size_t kn = (k + 1) % 3;
          if (q[k].y() != y_top || q[kn].y() != y_top) continue;
          const int g = unfoldings[static_cast<std::size_t>(f)][k].face;
          if (g < 0 || used[static_cast<std::size_t>(g)] ||
              patches[static_cast<std::size_t>(g)].frame.z_axis.dot(seed_normal) < min_cos)
            continue;
          // The edge runs right to left along f's top, so left to right in g.
          const int g0 = CornerOf(mesh, g, fv[kn]);
          if (g0 < 0 ||
              mesh.faces[static_cast<std::size_t>(g)][static_cast<std::size_t>((g0 + 1) % 3)] !=
                  fv[k])
            continue;
          const double key = std::abs(0.5 * (q[k].x() + q[kn].x() - anchor_lo - anchor_hi));
          if (key < next_key) next = g, next_k0 = static_cast<std::size_t>(g0), next_key = key;
        }
      }
      if (next < 0) break;
      const Corners cn = FrameCornersTexels(patches[static_cast<std::size_t>(next)], t);
      const std::size_t n0 = next_k0, n1 = (n0 + 1) % 3, n2 = (n0 + 2) % 3;
      const double edge = (cn[n1] - cn[n0]).norm();
      if (!(edge > 0.0)) break;
      const double height = Cross(cn[n1] - cn[n0], cn[n2] - cn[n0]) / edge;
      const double next_height = band_height_for(height);
      if (stack_height + next_height > options.max_stack_texels) break;
      const auto& nv = mesh.faces[static_cast<std::size_t>(next)];
      Corners qn;
      qn[n0] = Eigen::Vector2d(anchor_x.at(nv[n0]), y_top);
      qn[n1] = Eigen::Vector2d(anchor_x.at(nv[n1]), y_top);
      // The apex by the similarity taking the edge onto its place, on the new top line.
      qn[n2] = Eigen::Vector2d(MapBySimilarity(cn[n0], cn[n1], qn[n0], qn[n1], cn[n2]).x(),
                               y_top + next_height);
      if (!within_overhang(qn[n2].x())) break;
      const double old_bottom = y_bottom, old_top = y_top;
      y_bottom = y_top;
      y_top = y_top + next_height;
      if (!place(next, qn)) {
        y_bottom = old_bottom, y_top = old_top;
        break;
      }
      mark_used(next);
      std::vector<std::pair<int, Corners>> layer = {{next, qn}};
      const auto [chart_lo, chart_hi] = XRange(band);
      Rung up_right{next, nv[n2], nv[n1], qn[n2], qn[n1]};
      for (auto& fq : grow(up_right, chart_lo, false).first) layer.push_back(fq);
      Rung up_left{next, nv[n0], nv[n2], TurnBand(qn[n0], y_bottom, y_top),
                   TurnBand(qn[n2], y_bottom, y_top)};
      for (auto& [f, q] : grow(up_left, -chart_hi, true).first) {
        for (auto& p : q) p = TurnBand(p, y_bottom, y_top);
        layer.emplace_back(f, q);
      }
      const auto [layer_lo, layer_hi] = XRange(layer);
      const double cover =
          (std::min(layer_hi, anchor_hi) - std::max(layer_lo, anchor_lo)) / (anchor_hi - anchor_lo);
      if (!(cover >= options.min_stack_cover)) {
        for (auto it = layer.rbegin(); it != layer.rend(); ++it) unmark_used(it->first);
        y_bottom = old_bottom, y_top = old_top;
        break;
      }
      for (const auto& fq : layer) band.push_back(fq);
      below = std::move(layer);
      stack_height += next_height;
      ++st.stacked;
    }
    anchor_x.clear();
    charts.push_back(ChartOfBand(patches, t, band));
  }
  return charts;
}

}  // namespace texlume::atlas
