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

#include "atlas/chart_parts.h"
#include "atlas/charts.h"
#include "atlas/fan_sectors.h"
#include "core/check.h"
#include "core/errors.h"
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

namespace {

// Band lines a hair outside texel centres, so the centres on them are inside.
constexpr double kInset = 1e-3;  // texels

/// MakeStripCharts' state: the faces used and the seed queue, the charts made,
/// and per band its lines, its faces and (when stacking) the chain it stands on.
class StripChartBuilder {
 public:
  StripChartBuilder(const mesh::TriangleMesh& mesh,
                    const std::vector<synth::TrianglePatch>& patches,
                    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                    const StripChartOptions& options, StripChartStats& st)
      : mesh_(mesh),
        patches_(patches),
        unfoldings_(unfoldings),
        options_(options),
        st_(st),
        t_(options.texel_size),
        min_cos_(std::cos(options.max_normal_angle_deg * kPi / 180.0)),
        // A seed within this relative distance of the preferred height takes it
        // (within the stretch bound, which also has to absorb the other faces).
        snap_to_preferred_(std::min(0.2, 0.8 * (options.max_stretch - 1.0))),
        preferred_height_(PreferredBandHeight(patches, t_)),
        used_(mesh.faces.size(), 0) {
    InitSeeds();
  }

  /// Charts the fans, then a strip from each seed until every face is used.
  std::vector<std::vector<ChartFace>> Run() {
    if (options_.min_fan_faces > 0) ChartFans();
    while (!seeds_.empty()) ChartStrip(std::get<2>(*seeds_.begin()));
    return std::move(charts_);
  }

 private:
  using BandFaces = std::vector<std::pair<int, Corners>>;

  /// Queues every face as a seed, keyed by its free neighbours and rank.
  void InitSeeds() {
    const std::size_t num_faces = mesh_.faces.size();
    // Seeds: the free face with the fewest free neighbours (so strips leave few
    // faces stranded), then the earliest in breadth-first order.
    const std::vector<int> bfs = SeedOrder(mesh_, unfoldings_);
    rank_.assign(num_faces, 0);
    free_neighbours_.assign(num_faces, 0);
    for (std::size_t i = 0; i < bfs.size(); ++i)
      rank_[static_cast<std::size_t>(bfs[i])] = static_cast<int>(i);
    for (std::size_t f = 0; f < num_faces; ++f) {
      for (const synth::Unfolding& u : unfoldings_[f]) free_neighbours_[f] += u.face >= 0 ? 1 : 0;
      seeds_.emplace(free_neighbours_[f], rank_[f], static_cast<int>(f));
    }
  }

  /// Marks face f used: off the seed queue, one free neighbour fewer for its neighbours.
  void MarkUsed(int f) {
    const auto fs = static_cast<std::size_t>(f);
    used_[fs] = 1;
    seeds_.erase({free_neighbours_[fs], rank_[fs], f});
    for (const synth::Unfolding& u : unfoldings_[fs]) {
      if (u.face < 0 || used_[static_cast<std::size_t>(u.face)]) continue;
      const auto g = static_cast<std::size_t>(u.face);
      seeds_.erase({free_neighbours_[g], rank_[g], u.face});
      --free_neighbours_[g];
      seeds_.emplace(free_neighbours_[g], rank_[g], u.face);
    }
  }

  /// Undoes MarkUsed (faces freed in the reverse order they were used).
  void UnmarkUsed(int f) {
    const auto fs = static_cast<std::size_t>(f);
    used_[fs] = 0;
    int free = 0;
    for (const synth::Unfolding& u : unfoldings_[fs]) {
      if (u.face < 0 || used_[static_cast<std::size_t>(u.face)]) continue;
      const auto g = static_cast<std::size_t>(u.face);
      seeds_.erase({free_neighbours_[g], rank_[g], u.face});
      ++free_neighbours_[g];
      seeds_.emplace(free_neighbours_[g], rank_[g], u.face);
      ++free;
    }
    free_neighbours_[fs] = free;
    seeds_.emplace(free, rank_[fs], f);
  }

  /// A band's height (whole texels) for a face of this height over its side edge.
  double BandHeightFor(double height) const {
    if (std::abs(height / preferred_height_ - 1.0) < snap_to_preferred_) return preferred_height_;
    if (!options_.fit_irregular_faces) return std::max(1.0, std::round(height));
    // Else the nearest height of the ladder preferred * s^k (s the stretch
    // bound): the face is stretched by at most sqrt(s) across the band, and the
    // bands of an irregular mesh share few heights, so they fill atlas rows.
    const double k =
        std::round(std::log(height / preferred_height_) / std::log(options_.max_stretch));
    return std::max(1.0, std::round(preferred_height_ * std::pow(options_.max_stretch, k)));
  }

  /// The face's map into the band when its stretch is within the bound.
  std::optional<ChartFace> Place(int f, const Corners& band) const {
    const Corners c = FrameCornersTexels(patches_[static_cast<std::size_t>(f)], t_);
    const double twice_area = Cross(band[1] - band[0], band[2] - band[0]);
    if (!(twice_area > 1e-6) || !(Cross(c[1] - c[0], c[2] - c[0]) > 1e-12)) return std::nullopt;
    ChartFace cf = AffineBetween(f, c, band);
    const Eigen::Vector2d sigma = SingularValues2(cf.linear);
    if (!(sigma.x() <= options_.max_stretch && sigma.y() >= 1.0 / options_.max_stretch))
      return std::nullopt;
    return cf;
  }

  /// Step 0: charts the fans around the vertices of most faces first.
  void ChartFans() {
    // 0. Fans: the free faces around a vertex of at least `min_fan_faces` faces
    // (cylinder caps, cone tips, the poles of latitude-longitude spheres) cannot
    // follow a band, since every face shares the centre. Each fan is unfolded
    // about its centre (rigid, stretch 1) and cut into sectors; a sector stands
    // in its band with the centre on the bottom line and its bisector upright, so
    // turned sectors nest between upright ones in an atlas row.
    const std::vector<std::vector<int>> faces_of_vertex = FacesOfVertex(mesh_);
    std::vector<int> centres;
    for (std::size_t v = 0; v < faces_of_vertex.size(); ++v)
      if (static_cast<int>(faces_of_vertex[v].size()) >= options_.min_fan_faces)
        centres.push_back(static_cast<int>(v));
    std::stable_sort(centres.begin(), centres.end(), [&](int a, int b) {
      return faces_of_vertex[static_cast<std::size_t>(a)].size() >
             faces_of_vertex[static_cast<std::size_t>(b)].size();
    });
    std::vector<char> in_fan(mesh_.faces.size(), 0);
    for (const int v : centres) ChartFan(v, faces_of_vertex[static_cast<std::size_t>(v)], in_fan);
  }

  /// Charts the free faces around centre v (`faces`) whose normals are near
  /// their mean as fans: each run of them cut into sectors, a chart each.
  void ChartFan(int v, const std::vector<int>& faces, std::vector<char>& in_fan) {
    std::vector<int> free_faces;
    Eigen::Vector3d mean_normal = Eigen::Vector3d::Zero();
    for (const int f : faces)
      if (!used_[static_cast<std::size_t>(f)]) {
        free_faces.push_back(f);
        mean_normal += patches_[static_cast<std::size_t>(f)].frame.z_axis;
      }
    if (static_cast<int>(free_faces.size()) < options_.min_fan_faces || !(mean_normal.norm() > 0))
      return;
    mean_normal.normalize();
    for (const int f : free_faces)
      in_fan[static_cast<std::size_t>(f)] =
          patches_[static_cast<std::size_t>(f)].frame.z_axis.dot(mean_normal) >= min_cos_;
    for (const std::vector<int>& run : FanRuns(mesh_, unfoldings_, v, free_faces, in_fan)) {
      const auto sectors = FanSectors(mesh_, patches_, unfoldings_, used_, v, run, t_,
                                      options_.gutter, options_.max_length_texels, 0.5 - kInset);
      if (sectors.empty()) continue;  // too short or too large: left to strips
      ++st_.fans;
      for (const auto& sector : sectors) {
        for (const auto& [f, q] : sector) MarkUsed(f);
        charts_.push_back(ChartOfBand(patches_, t_, sector));
        ++st_.fan_sectors;
      }
    }
    for (const int f : free_faces) in_fan[static_cast<std::size_t>(f)] = 0;
  }

  /// Charts a strip from `seed` (steps 1-4), or the seed alone when it fits no band.
  void ChartStrip(int seed) {
    const Corners c = FrameCornersTexels(patches_[static_cast<std::size_t>(seed)], t_);
    seed_normal_ = patches_[static_cast<std::size_t>(seed)].frame.z_axis;
    const auto [side, side_height] = SeedSide(seed, c);
    const double band_height = BandHeightFor(side_height);
    // The band's lines; a stacked band moves them up (step 4).
    y_bottom_ = 0.5 - kInset;
    y_top_ = 0.5 + band_height + kInset;
    std::optional<ChartFace> seed_placement;
    Corners seed_band;
    if (side >= 0) {
      const auto k0 = static_cast<std::size_t>(side), k1 = (k0 + 1) % 3, k2 = (k0 + 2) % 3;
      const Eigen::Vector2d along = (c[k1] - c[k0]).normalized();
      seed_band[k0] = Eigen::Vector2d(0.0, y_bottom_);
      seed_band[k1] = Eigen::Vector2d((c[k1] - c[k0]).norm(), y_bottom_);
      seed_band[k2] = Eigen::Vector2d((c[k2] - c[k0]).dot(along), y_top_);
      seed_placement = Place(seed, seed_band);
    }
    MarkUsed(seed);
    if (!seed_placement) {  // degenerate or too small for a band: on its own, rigid
      ++st_.lone_faces;
      charts_.push_back({ChartFace{seed, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero()}});
      return;
    }
    ++st_.strips;
    band_ = {{seed, seed_band}};
    anchor_x_.clear();
    anchor_lo_ = 0.0, anchor_hi_ = 0.0;
    GrowSeed(seed, side, seed_band);
    SquareEnds();
    Stack(band_height);
    anchor_x_.clear();
    charts_.push_back(ChartOfBand(patches_, t_, band_));
  }

  /// Step 1: the seed's side edge (-1: none) and the seed's height over it.
  std::pair<int, double> SeedSide(int seed, const Corners& c) const {
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
      const int across = unfoldings_[static_cast<std::size_t>(seed)][ks].face;
      const bool borders = across < 0 || used_[static_cast<std::size_t>(across)];
      // Prefer: along the charted region, then the tallest (or the nearest the
      // preferred height).
      const double h_key = options_.side == StripSide::kNearestPreferred
                               ? -std::abs(height - preferred_height_)
                               : height;
      const auto key = std::make_tuple(borders, h_key);
      if (side < 0 || key > side_key) side = k, side_key = key, side_height = height;
    }
    return {side, side_height};
  }

  /// Whether x is within the overhang allowed beyond the chain below.
  bool WithinOverhang(double x) const {
    // A stacked band stays within `max_stack_overhang_texels` beyond the ends
    // of the chain it stands on, so stacks stay near rectangles.
    return options_.max_stack_overhang_texels < 0.0 ||
           (x >= anchor_lo_ - options_.max_stack_overhang_texels &&
            x <= anchor_hi_ + options_.max_stack_overhang_texels);
  }

  /// In a stacked band, the x of face g's apex going onto the free line, by
  /// the similarity of the next face across (apex, the rung's end on the band
  /// below), whose edge on that band has both ends where the band put them; not
  /// by the rung's, so the differences between the two lines' lengths (a torus
  /// ring's circles) do not add up along the band. None when that face is used
  /// or its third corner is not on the band below.
  std::optional<double> FreeLineX(int g, int apex_vertex, const Rung& rung, bool turned,
                                  bool apex_on_top) const {
    const int on_line = turned ? rung.top : rung.bottom;  // the rung's end on the band below
    const Eigen::Vector2d& on_line_xy = turned ? rung.top_xy : rung.bottom_xy;
    const int h = FaceAcross(mesh_, unfoldings_, g, apex_vertex, on_line);
    if (h < 0 || used_[static_cast<std::size_t>(h)]) return std::nullopt;
    const int h_on_line = CornerOf(mesh_, h, on_line), h_apex = CornerOf(mesh_, h, apex_vertex);
    if (h_on_line < 0 || h_apex < 0) return std::nullopt;
    const auto hs = static_cast<std::size_t>(h);
    const auto h_next = static_cast<std::size_t>(3 - h_on_line - h_apex);
    const auto it = anchor_x_.find(mesh_.faces[hs][h_next]);
    if (it == anchor_x_.end()) return std::nullopt;
    const double next_x = turned ? -it->second : it->second;
    if (!(next_x > on_line_xy.x() + 1e-3)) return std::nullopt;
    const Corners ph = FrameCornersTexels(patches_[hs], t_);
    const Eigen::Vector2d q = MapBySimilarity(ph[static_cast<std::size_t>(h_on_line)], ph[h_next],
                                              on_line_xy, Eigen::Vector2d(next_x, on_line_xy.y()),
                                              ph[static_cast<std::size_t>(h_apex)]);
    if ((q.y() > on_line_xy.y()) != apex_on_top) return std::nullopt;
    return q.x();
  }

  /// 2. Growth towards +x across `rung` while faces fit; `lo` is the band's
  /// far end in this direction's coordinates (`turned`: the band turned by
  /// 180 degrees, growing towards -x). Returns the faces added and their largest x.
  std::pair<BandFaces, double> Grow(Rung rung, double lo, bool turned) {
    BandFaces added;
    double hi = -std::numeric_limits<double>::max();
    for (;;) {
      const int g = FaceAcross(mesh_, unfoldings_, rung.face, rung.top, rung.bottom);
      if (g < 0 || used_[static_cast<std::size_t>(g)]) break;
      if (patches_[static_cast<std::size_t>(g)].frame.z_axis.dot(seed_normal_) < min_cos_) break;
      const int k_top = CornerOf(mesh_, g, rung.top), k_bottom = CornerOf(mesh_, g, rung.bottom);
      if (k_top < 0 || k_bottom < 0) break;
      const int k_apex = 3 - k_top - k_bottom;
      const Corners p = FrameCornersTexels(patches_[static_cast<std::size_t>(g)], t_);
      // The similarity taking the rung's frame points onto its band points.
      if (p[k_top] == p[k_bottom]) break;
      const Eigen::Vector2d apex_mapped =
          MapBySimilarity(p[k_bottom], p[k_top], rung.bottom_xy, rung.top_xy, p[k_apex]);
      // The apex goes to the nearer band line and must lie beyond the rung's
      // end on that line (bands are monotone, so faces never overlap).
      bool apex_on_top = apex_mapped.y() > 0.5 * (y_bottom_ + y_top_);
      Eigen::Vector2d apex(apex_mapped.x(), apex_on_top ? y_top_ : y_bottom_);
      const int apex_vertex =
          mesh_.faces[static_cast<std::size_t>(g)][static_cast<std::size_t>(k_apex)];
      if (!anchor_x_.empty() && apex_on_top != turned)
        if (const auto x = FreeLineX(g, apex_vertex, rung, turned, apex_on_top)) apex.x() = *x;
      if (!anchor_x_.empty() && !WithinOverhang(turned ? -apex.x() : apex.x())) break;
      if (!anchor_x_.empty() && apex_on_top == turned) {  // onto the band below
        const auto it = anchor_x_.find(apex_vertex);
        const double x = turned ? -apex.x() : apex.x();
        if (it != anchor_x_.end())
          apex.x() = turned ? -it->second : it->second;
        else if (x > anchor_lo_ - 1.0 && x < anchor_hi_ + 1.0)
          break;
      }
      if (apex.x() <= (apex_on_top ? rung.top_xy.x() : rung.bottom_xy.x()) + 1e-3) break;
      if (std::max(hi, apex.x()) - lo > options_.max_length_texels) break;
      Corners q;
      q[static_cast<std::size_t>(k_top)] = rung.top_xy;
      q[static_cast<std::size_t>(k_bottom)] = rung.bottom_xy;
      q[static_cast<std::size_t>(k_apex)] = apex;
      bool fits = Place(g, q).has_value();
      if (!fits && options_.fit_irregular_faces && anchor_x_.empty()) {
        // An irregular face the rung's similarity stretches too far: its apex
        // at the least-stretching place on either line instead.
        const auto ka = static_cast<std::size_t>(k_apex);
        double least = std::numeric_limits<double>::infinity();
        for (const bool on_top : {apex_on_top, !apex_on_top}) {
          const double x_min = (on_top ? rung.top_xy.x() : rung.bottom_xy.x()) + 1e-3;
          const auto [x, s] = LeastStretchOnLine(p, q, ka, on_top ? y_top_ : y_bottom_, x_min);
          if (s < least) least = s, apex = Eigen::Vector2d(x, on_top ? y_top_ : y_bottom_);
        }
        apex_on_top = apex.y() == y_top_;
        q[ka] = apex;
        if (std::max(hi, apex.x()) - lo > options_.max_length_texels) break;
        fits = Place(g, q).has_value();
      }
      if (!fits) break;
      MarkUsed(g);
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
  }

  /// Grows the seed's strip both ways: towards +x, then towards -x in the turned band.
  void GrowSeed(int seed, int side, const Corners& seed_band) {
    const double lo_x = std::min({seed_band[0].x(), seed_band[1].x(), seed_band[2].x()});
    double hi_x = std::max({seed_band[0].x(), seed_band[1].x(), seed_band[2].x()});
    const auto k0 = static_cast<std::size_t>(side), k1 = (k0 + 1) % 3, k2 = (k0 + 2) % 3;
    const auto& sv = mesh_.faces[static_cast<std::size_t>(seed)];
    // Towards +x across (apex, v1).
    Rung right{seed, sv[k2], sv[k1], seed_band[k2], seed_band[k1]};
    auto [to_right, right_hi] = Grow(right, lo_x, false);
    for (auto& fq : to_right) band_.push_back(fq);
    if (!to_right.empty()) hi_x = std::max(hi_x, right_hi);
    // Towards -x across (v0, apex), grown in the band turned by 180 degrees.
    Rung left{seed, sv[k0], sv[k2], TurnBand(seed_band[k0], y_bottom_, y_top_),
              TurnBand(seed_band[k2], y_bottom_, y_top_)};
    auto to_left = Grow(left, -hi_x, true).first;
    for (auto& [f, q] : to_left) {
      for (auto& p : q) p = TurnBand(p, y_bottom_, y_top_);
      band_.emplace_back(f, q);
    }
  }

  /// The outermost x of the band's corners on line y_line at its right or left end.
  double EndX(bool right_end, double y_line) const {
    double x = right_end ? -std::numeric_limits<double>::max() : std::numeric_limits<double>::max();
    for (const auto& fq : band_)
      for (const auto& p : fq.second)
        if (p.y() == y_line) x = right_end ? std::max(x, p.x()) : std::min(x, p.x());
    return x;
  }

  /// Step 3: squares the band's ends where the stretch bound allows.
  void SquareEnds() {
    // 3. Square ends: each end rung is made to cross the band straight (its
    // two ends moved to their mean, or one onto the other) when the faces on it
    // stay within the stretch bound, so bands abut in atlas rows.
    for (const bool right_end : {true, false}) {
      const double x_top = EndX(right_end, y_top_), x_bottom = EndX(right_end, y_bottom_);
      for (const double x : {0.5 * (x_top + x_bottom), x_top, x_bottom}) {
        auto moved = band_;
        bool ok = true;
        for (auto& [f, q] : moved) {
          bool touched = false;
          for (auto& p : q)
            if ((p.y() == y_top_ && p.x() == x_top) || (p.y() == y_bottom_ && p.x() == x_bottom)) {
              p.x() = x;
              touched = true;
            }
          if (touched && !Place(f, q)) ok = false;
        }
        if (ok) {
          band_ = std::move(moved);
          break;
        }
      }
    }
  }

  /// Step 4: stacks bands on the band's top line while they fit.
  void Stack(double band_height) {
    // 4. Stacking: a band grown on the top line of the last one, from a free
    // face across one of its top edges, shares that line (no gutter rows
    // between them). It is kept when it covers most of the band below and the
    // stack stays within `max_stack_texels`; else its faces are freed.
    BandFaces below = band_;
    double stack_height = band_height;
    bool more = options_.max_stack_texels > 0.0;
    while (more) more = StackBand(below, stack_height);
  }

  /// Anchors the next band on the top chain of `below`: its vertices' x and span.
  void SetAnchors(const BandFaces& below) {
    anchor_x_.clear();
    anchor_lo_ = std::numeric_limits<double>::max();
    anchor_hi_ = -anchor_lo_;
    for (const auto& [f, q] : below)
      for (std::size_t k = 0; k < 3; ++k)
        if (q[k].y() == y_top_) {
          anchor_x_[mesh_.faces[static_cast<std::size_t>(f)][k]] = q[k].x();
          anchor_lo_ = std::min(anchor_lo_, q[k].x());
          anchor_hi_ = std::max(anchor_hi_, q[k].x());
        }
  }

  /// The stacked band's seed and its corner starting the edge on the chain (-1: none).
  std::pair<int, std::size_t> StackSeed(const BandFaces& below) const {
    // The seed: across the top edge nearest the middle of the chain.
    int next = -1;
    std::size_t next_k0 = 0;
    double next_key = std::numeric_limits<double>::max();
    for (const auto& [f, q] : below) {
      const auto& fv = mesh_.faces[static_cast<std::size_t>(f)];
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t kn = (k + 1) % 3;
        if (q[k].y() != y_top_ || q[kn].y() != y_top_) continue;
        const int g = unfoldings_[static_cast<std::size_t>(f)][k].face;
        if (g < 0 || used_[static_cast<std::size_t>(g)] ||
            patches_[static_cast<std::size_t>(g)].frame.z_axis.dot(seed_normal_) < min_cos_)
          continue;
        // The edge runs right to left along f's top, so left to right in g.
        const int g0 = CornerOf(mesh_, g, fv[kn]);
        if (g0 < 0 ||
            mesh_.faces[static_cast<std::size_t>(g)][static_cast<std::size_t>((g0 + 1) % 3)] !=
                fv[k])
          continue;
        const double key = std::abs(0.5 * (q[k].x() + q[kn].x() - anchor_lo_ - anchor_hi_));
        if (key < next_key) next = g, next_k0 = static_cast<std::size_t>(g0), next_key = key;
      }
    }
    return {next, next_k0};
  }

  /// Grows a band on the top line of `below` and keeps it when it fits and
  /// covers `below`; then it is the new `below`. False when none was kept.
  bool StackBand(BandFaces& below, double& stack_height) {
    SetAnchors(below);
    const auto [next, next_k0] = StackSeed(below);
    if (next < 0) return false;
    const Corners cn = FrameCornersTexels(patches_[static_cast<std::size_t>(next)], t_);
    const std::size_t n0 = next_k0, n1 = (n0 + 1) % 3, n2 = (n0 + 2) % 3;
    const double edge = (cn[n1] - cn[n0]).norm();
    if (!(edge > 0.0)) return false;
    const double height = Cross(cn[n1] - cn[n0], cn[n2] - cn[n0]) / edge;
    const double next_height = BandHeightFor(height);
    if (stack_height + next_height > options_.max_stack_texels) return false;
    const auto& nv = mesh_.faces[static_cast<std::size_t>(next)];
    Corners qn;
    qn[n0] = Eigen::Vector2d(anchor_x_.at(nv[n0]), y_top_);
    qn[n1] = Eigen::Vector2d(anchor_x_.at(nv[n1]), y_top_);
    // The apex by the similarity taking the edge onto its place, on the new top line.
    qn[n2] = Eigen::Vector2d(MapBySimilarity(cn[n0], cn[n1], qn[n0], qn[n1], cn[n2]).x(),
                             y_top_ + next_height);
    if (!WithinOverhang(qn[n2].x())) return false;
    const double old_bottom = y_bottom_, old_top = y_top_;
    y_bottom_ = y_top_;
    y_top_ = y_top_ + next_height;
    if (!Place(next, qn)) {
      y_bottom_ = old_bottom, y_top_ = old_top;
      return false;
    }
    MarkUsed(next);
    BandFaces layer = {{next, qn}};
    const auto [chart_lo, chart_hi] = XRange(band_);
    Rung up_right{next, nv[n2], nv[n1], qn[n2], qn[n1]};
    for (auto& fq : Grow(up_right, chart_lo, false).first) layer.push_back(fq);
    Rung up_left{next, nv[n0], nv[n2], TurnBand(qn[n0], y_bottom_, y_top_),
                 TurnBand(qn[n2], y_bottom_, y_top_)};
    for (auto& [f, q] : Grow(up_left, -chart_hi, true).first) {
      for (auto& p : q) p = TurnBand(p, y_bottom_, y_top_);
      layer.emplace_back(f, q);
    }
    const auto [layer_lo, layer_hi] = XRange(layer);
    const double cover = (std::min(layer_hi, anchor_hi_) - std::max(layer_lo, anchor_lo_)) /
                         (anchor_hi_ - anchor_lo_);
    if (!(cover >= options_.min_stack_cover)) {
      for (auto it = layer.rbegin(); it != layer.rend(); ++it) UnmarkUsed(it->first);
      y_bottom_ = old_bottom, y_top_ = old_top;
      return false;
    }
    for (const auto& fq : layer) band_.push_back(fq);
    below = std::move(layer);
    stack_height += next_height;
    ++st_.stacked;
    return true;
  }

  const mesh::TriangleMesh& mesh_;
  const std::vector<synth::TrianglePatch>& patches_;
  const std::vector<std::array<synth::Unfolding, 3>>& unfoldings_;
  const StripChartOptions& options_;
  StripChartStats& st_;
  const double t_;
  const double min_cos_;
  const double snap_to_preferred_;
  const double preferred_height_;

  std::vector<char> used_;
  std::vector<int> rank_, free_neighbours_;
  std::set<std::tuple<int, int, int>> seeds_;  // (free neighbours, rank, face)
  std::vector<std::vector<ChartFace>> charts_;

  // The band being grown: its seed's normal, its lines, its faces' corners in
  // band texels.
  Eigen::Vector3d seed_normal_ = Eigen::Vector3d::Zero();
  double y_bottom_ = 0.0, y_top_ = 0.0;
  BandFaces band_;
  // A stacked band's bottom line is the top line of the band under it: the
  // vertices of that band's top chain keep their x there, and no other
  // vertex may land on the line within the chain's span (step 4).
  std::unordered_map<int, double> anchor_x_;
  double anchor_lo_ = 0.0, anchor_hi_ = 0.0;
};

}  // namespace

std::vector<std::vector<ChartFace>> MakeStripCharts(
    const mesh::TriangleMesh& mesh, const std::vector<synth::TrianglePatch>& patches,
    const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
    const StripChartOptions& options, StripChartStats* stats) {
  const std::size_t num_faces = mesh.faces.size();
  TEXLUME_CHECK(patches.size() == num_faces && unfoldings.size() == num_faces,
                "charts need one patch and one unfolding per face");
  options.Check();
  StripChartStats local_stats;
  return StripChartBuilder(mesh, patches, unfoldings, options, stats ? *stats : local_stats).Run();
}

}  // namespace texlume::atlas
