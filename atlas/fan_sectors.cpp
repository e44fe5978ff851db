#include "atlas/fan_sectors.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <queue>
#include <set>

#include "core/check.h"
#include "mesh/triangle_frame.h"

namespace texlume::atlas::chart_parts {
namespace {

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

/// The stages of FanSectors: the run unfolded about its centre, the free faces
/// beyond a flat run, the number of sectors and their cuts, then the sectors.
class FanSectorCutter {
 public:
  FanSectorCutter(const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
                  const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                  const std::vector<char>& used, int v, const std::vector<int>& run, double t,
                  int gutter, double max_length, double y_bottom)
      : mesh_(mesh),
        patches_(patches),
        unfoldings_(unfoldings),
        used_(used),
        v_(v),
        run_(run),
        t_(t),
        gutter_(gutter),
        max_length_(max_length),
        y_bottom_(y_bottom) {}

  /// Runs the stages: per sector its faces' corners in band texels, or empty.
  std::vector<std::vector<std::pair<int, Corners>>> Cut() {
    Unfold();
    const std::size_t m = unfolded_.size();
    if (m < 3) return {};
    if (IsFlat()) TakeFacesBeyond();
    if (radius_ + 2.0 * gutter_ > max_length_) return {};
    const std::size_t sectors = SectorCount();
    if (sectors == 0) return {};
    const std::vector<std::size_t> cuts = Cuts(sectors);
    std::vector<std::vector<std::pair<int, Corners>>> out;
    for (std::size_t s = 0; s + 1 < cuts.size(); ++s) out.push_back(Sector(cuts[s], cuts[s + 1]));
    return out;
  }

 private:
  /// Unfolds the run's faces rigidly about v, each across the edge it shares
  /// with the one before, until the run ends or its orientation flips.
  void Unfold() {
    int previous_last = -1;  // the previous face's second edge's far vertex
    for (const int f : run_) {
      const int k = CornerOf(mesh_, f, v_);
      const auto ks = static_cast<std::size_t>(k), a = (ks + 1) % 3, b = (ks + 2) % 3;
      const auto& fv = mesh_.faces[static_cast<std::size_t>(f)];
      if (previous_last >= 0 && fv[a] != previous_last) break;  // orientation flips: run ends
      const Corners c = FrameCornersTexels(patches_[static_cast<std::size_t>(f)], t_);
      const Eigen::Vector2d ea = c[a] - c[ks], eb = c[b] - c[ks];
      const double theta = std::atan2(Cross(ea, eb), ea.dot(eb));
      if (!(theta > 1e-9) || !(ea.norm() > 0.0)) break;
      const Eigen::Matrix2d turn =
          Eigen::Rotation2Dd(phi_.back() - std::atan2(ea.y(), ea.x())).toRotationMatrix();
      Corners q;
      q[ks] = Eigen::Vector2d::Zero();
      q[b] = turn * eb;
      if (unfolded_.empty()) {
        q[a] = turn * ea;
      } else {  // the shared edge exactly where the previous face put it
        const int pk = CornerOf(mesh_, run_[unfolded_.size() - 1], v_);
        q[a] = unfolded_.back()[static_cast<std::size_t>((pk + 2) % 3)];
      }
      unfolded_.push_back(q);
      phi_.push_back(phi_.back() + theta);
      radius_ = std::max({radius_, ea.norm(), eb.norm()});
      previous_last = fv[b];
    }
  }

  /// Whether the unfolded faces are coplanar (normals within a quarter degree).
  bool IsFlat() const {
    const Eigen::Vector3d& normal = patches_[static_cast<std::size_t>(run_[0])].frame.z_axis;
    bool flat = true;
    for (std::size_t i = 0; i < unfolded_.size(); ++i)
      flat =
          flat && patches_[static_cast<std::size_t>(run_[i])].frame.z_axis.dot(normal) >= flat_cos_;
    return flat;
  }

  /// The free faces of a flat run's plane beyond it, found breadth first.
  void TakeFacesBeyond() {
    // A flat run takes in the free faces of its plane beyond it, reached across
    // edges, whose centroids lie within its angles (the plane's coordinates: x
    // along the first face's first edge, counter-clockwise about the normal).
    const std::size_t m = unfolded_.size();
    const double total = phi_.back();
    const Eigen::Vector3d& normal = patches_[static_cast<std::size_t>(run_[0])].frame.z_axis;
    const Eigen::Vector3d& centre = mesh_.vertices[static_cast<std::size_t>(v_)];
    const int first_a =
        mesh_.faces[static_cast<std::size_t>(run_[0])]
                   [static_cast<std::size_t>((CornerOf(mesh_, run_[0], v_) + 1) % 3)];
    Eigen::Vector3d e1 = mesh_.vertices[static_cast<std::size_t>(first_a)] - centre;
    e1 = (e1 - e1.dot(normal) * normal).normalized();
    const Eigen::Vector3d e2 = normal.cross(e1);
    auto plane = [&](int w) -> Eigen::Vector2d {
      const Eigen::Vector3d d = mesh_.vertices[static_cast<std::size_t>(w)] - centre;
      return Eigen::Vector2d(d.dot(e1), d.dot(e2)) / t_;
    };
    std::set<int> taken(run_.begin(), run_.begin() + static_cast<std::ptrdiff_t>(m));
    std::deque<int> queue(run_.begin(), run_.begin() + static_cast<std::ptrdiff_t>(m));
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      for (const synth::Unfolding& u : unfoldings_[static_cast<std::size_t>(f)]) {
        const int g = u.face;
        if (g < 0 || used_[static_cast<std::size_t>(g)] || taken.count(g) ||
            patches_[static_cast<std::size_t>(g)].frame.z_axis.dot(normal) < flat_cos_)
          continue;
        Corners q;
        for (std::size_t k = 0; k < 3; ++k)
          q[k] = plane(mesh_.faces[static_cast<std::size_t>(g)][k]);
        const Eigen::Vector2d centroid = (q[0] + q[1] + q[2]) / 3.0;
        double angle = std::atan2(centroid.y(), centroid.x());
        if (angle < 0.0) angle += 2.0 * kPi;
        if (!(angle < total)) continue;
        taken.insert(g);
        queue.push_back(g);
        beyond_.push_back(g);
        beyond_q_.push_back(q);
        beyond_angle_.push_back(angle);
        for (const auto& p : q) radius_ = std::max(radius_, p.norm());
      }
    }
  }

  /// The number of sectors of least row area, each at most 90 degrees (0: none fits).
  std::size_t SectorCount() const {
    constexpr double kMaxSectorAngle = 0.5 * kPi;
    const std::size_t m = unfolded_.size();
    const double total = phi_.back();
    std::size_t sectors = 0;
    double best_cost = std::numeric_limits<double>::max();
    for (std::size_t n = 1; n <= m; ++n) {
      const double beta = total / static_cast<double>(n);
      if (beta > kMaxSectorAngle && n < m) continue;
      if (2.0 * radius_ * std::sin(0.5 * std::min(beta, kPi)) > max_length_) continue;
      const double cost = static_cast<double>(n) * (radius_ * radius_ * std::tan(0.5 * beta) +
                                                    2.0 * gutter_ * radius_ / std::cos(0.5 * beta));
      if (beta < kPi && cost < best_cost) best_cost = cost, sectors = n;
    }
    return sectors;
  }

  /// The run's indices where `sectors` sectors start, then its end.
  std::vector<std::size_t> Cuts(std::size_t sectors) const {
    const std::size_t m = unfolded_.size();
    const double total = phi_.back();
    // Cuts at the face edges nearest to equal angles.
    std::vector<std::size_t> cuts = {0};
    for (std::size_t j = 1; j < sectors; ++j) {
      const double target = total * static_cast<double>(j) / static_cast<double>(sectors);
      std::size_t best = cuts.back() + 1;
      for (std::size_t i = best; i <= m - (sectors - j); ++i)  // leave a face per sector after
        if (std::abs(phi_[i] - target) < std::abs(phi_[best] - target)) best = i;
      cuts.push_back(best);
    }
    cuts.push_back(m);
    return cuts;
  }

  /// The sector of the run's faces [begin, end) and the faces beyond within its
  /// angles, turned upright with v at (0, y_bottom).
  std::vector<std::pair<int, Corners>> Sector(std::size_t begin, std::size_t end) const {
    const double mid = 0.5 * (phi_[begin] + phi_[end]);
    const Eigen::Matrix2d upright = Eigen::Rotation2Dd(0.5 * kPi - mid).toRotationMatrix();
    std::vector<std::pair<int, Corners>> sector;
    std::set<int> in_sector;
    for (std::size_t i = begin; i < end; ++i) {
      sector.emplace_back(run_[i], unfolded_[i]);
      in_sector.insert(run_[i]);
    }
    // The faces beyond within the sector's angles, reached from its own faces.
    for (bool grew = true; grew;) {
      grew = false;
      for (std::size_t j = 0; j < beyond_.size(); ++j) {
        if (in_sector.count(beyond_[j]) || beyond_angle_[j] < phi_[begin] ||
            beyond_angle_[j] >= phi_[end])
          continue;
        bool touches = false;
        for (const synth::Unfolding& u : unfoldings_[static_cast<std::size_t>(beyond_[j])])
          touches = touches || (u.face >= 0 && in_sector.count(u.face));
        if (!touches) continue;
        sector.emplace_back(beyond_[j], beyond_q_[j]);
        in_sector.insert(beyond_[j]);
        grew = true;
      }
    }
    for (auto& [f, q] : sector)
      for (auto& p : q) p = upright * p + Eigen::Vector2d(0.0, y_bottom_);
    return sector;
  }

  const mesh::TriangleMesh& mesh_;
  const std::vector<synth::TrianglePatch>& patches_;
  const std::vector<std::array<synth::Unfolding, 3>>& unfoldings_;
  const std::vector<char>& used_;
  const int v_;
  const std::vector<int>& run_;
  const double t_;
  const int gutter_;
  const double max_length_, y_bottom_;
  const double flat_cos_ = std::cos(0.25 * kPi / 180.0);  // coplanar faces

  std::vector<Corners> unfolded_;
  // The angle about v of each face's first edge, then of the last face's second.
  std::vector<double> phi_ = {0.0};
  double radius_ = 0.0;
  // The free faces beyond a flat run: their corners in its plane (texels) and
  // their centroids' angles about v.
  std::vector<int> beyond_;
  std::vector<Corners> beyond_q_;
  std::vector<double> beyond_angle_;
};

}  // namespace

int CornerOf(const mesh::TriangleMesh& mesh, int face, int vertex) {
  for (int k = 0; k < 3; ++k)
    if (mesh.faces[static_cast<std::size_t>(face)][static_cast<std::size_t>(k)] == vertex) return k;
  return -1;
}

/// The face across edge (a, b) of `face`, or -1.
int FaceAcross(const mesh::TriangleMesh& mesh,
               const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, int face, int a,
               int b) {
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

/// The faces `in_fan` marks around `v`, as runs in counter-clockwise order:
/// each run starts where its clockwise neighbour is not in the fan; a closed
/// ring starts at its lowest face.
std::vector<std::vector<int>> FanRuns(
    const mesh::TriangleMesh& mesh, const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    int v, const std::vector<int>& faces, const std::vector<char>& in_fan) {
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
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings, const std::vector<char>& used,
    int v, const std::vector<int>& run, double t, int gutter, double max_length, double y_bottom) {
  return FanSectorCutter(mesh, patches, unfoldings, used, v, run, t, gutter, max_length, y_bottom)
      .Cut();
}

}  // namespace texlume::atlas::chart_parts
