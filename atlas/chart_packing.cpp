#include "atlas/chart_packing.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <optional>
#include <unordered_map>

#include "atlas/charts.h"
#include "atlas/packing_bin.h"
#include "core/check.h"
#include "core/errors.h"
#include "ptm/coefficient_space.h"
#include "synth/planar_synthesis.h"

namespace texlume::atlas::chart_packing {

std::pair<int, int> TexelColumns(const std::pair<double, double>& span, int width) {
  if (span.first > span.second) return {0, -1};
  const double first = std::ceil(span.first - 0.5), last = std::floor(span.second - 0.5);
  return {static_cast<int>(std::max(0.0, first)),
          static_cast<int>(std::min(static_cast<double>(width - 1), last))};
}

ChartOutline Box(const std::vector<ChartFace>& chart, double angle,
                 const std::vector<synth::TrianglePatch>& patches, double t, int gutter,
                 std::vector<std::array<Eigen::Vector2d, 3>>* corners) {
  ChartOutline o;
  o.angle = angle;
  const Eigen::Matrix2d turn = Eigen::Rotation2Dd(angle).toRotationMatrix();
  Eigen::Vector2d lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (const ChartFace& cf : chart) {
    std::array<Eigen::Vector2d, 3> c;
    for (std::size_t k = 0; k < 3; ++k) {
      c[k] = turn *
             (cf.linear * patches[static_cast<std::size_t>(cf.face)].corners_in_frame[k] +
              cf.translation) /
             t;
      lo = lo.cwiseMin(c[k]);
      hi = hi.cwiseMax(c[k]);
    }
    if (corners) corners->push_back(c);
  }
  // Texels i whose centre i + 0.5 is within gutter + 0.5 (and a hair) of the corners' box.
  constexpr double kHair = 1e-6;
  o.lo = Eigen::Vector2i(static_cast<int>(std::ceil(lo.x() - gutter - 1 - kHair)),
                         static_cast<int>(std::ceil(lo.y() - gutter - 1 - kHair)));
  o.hi = Eigen::Vector2i(static_cast<int>(std::floor(hi.x() + gutter + kHair)) + 1,
                         static_cast<int>(std::floor(hi.y() + gutter + kHair)) + 1);
  return o;
}

namespace {

// The outline's runs, first texel per row and area from its mask (box size, 1 inside).
void RunsFromMask(const cv::Mat& mask, ChartOutline& o) {
  const int w = mask.cols, h = mask.rows;
  o.row_first_x.assign(static_cast<std::size_t>(h), std::numeric_limits<int>::max());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w;) {
      if (!mask.at<std::uint8_t>(y, x)) {
        ++x;
        continue;
      }
      int end = x;
      while (end < w && mask.at<std::uint8_t>(y, end)) ++end;
      o.runs.push_back({y, x, end - x});
      int& first = o.row_first_x[static_cast<std::size_t>(y)];
      first = std::min(first, x);
      o.area += end - x;
      x = end;
    }
  // Longest runs first: they reject a blocked position soonest.
  std::stable_sort(
      o.runs.begin(), o.runs.end(),
      [](const ChartOutline::Run& a, const ChartOutline::Run& b) { return a.length > b.length; });
}

}  // namespace

ChartOutline Outline(const std::vector<ChartFace>& chart, double angle,
                     const std::vector<synth::TrianglePatch>& patches, double t, int gutter) {
  std::vector<std::array<Eigen::Vector2d, 3>> corners;  // texels, chart frame
  ChartOutline o = Box(chart, angle, patches, t, gutter, &corners);
  const int w = o.Width(), h = o.Height();
  cv::Mat mask = cv::Mat::zeros(h, w, CV_8UC1);
  for (auto c : corners) {
    for (auto& p : c) p = Eigen::Vector2d(p.x() - o.lo.x(), o.hi.y() - p.y());  // box, y down
    Eigen::Vector2d clo = c[0], chi = clo;
    for (const auto& p : c) clo = clo.cwiseMin(p), chi = chi.cwiseMax(p);
    // Texels the bake writes for this face: centre within gutter + 0.5 of it
    // (and a hair more, so rounding in the bake cannot write beyond the outline).
    const double reach = gutter + 0.5 + 1e-6;
    for (int y = std::max(0, static_cast<int>(clo.y()) - gutter - 1);
         y <= std::min(h - 1, static_cast<int>(chi.y()) + gutter + 1); ++y) {
      auto [x_first, x_last] = TexelColumns(mesh::TriangleRowSpan(c, y + 0.5, reach), w);
      // The points within reach of a triangle are convex: on a row, one run of texels.
      // Centres on the row's chord of the triangle itself are within reach: no test;
      // outside it, the run's ends are found from the span's ends inwards.
      const std::pair<double, double> chord = mesh::TriangleRowSpan(c, y + 0.5, 0.0);
      const auto within = [&](int x) {
        return (x + 0.5 >= chord.first && x + 0.5 <= chord.second) ||
               mesh::WithinReachOfTriangle(c, Eigen::Vector2d(x + 0.5, y + 0.5), reach);
      };
      while (x_first <= x_last && !within(x_first)) ++x_first;
      while (x_last > x_first && !within(x_last)) --x_last;
      if (x_first <= x_last)
        std::fill_n(mask.ptr<std::uint8_t>(y) + x_first, x_last - x_first + 1, std::uint8_t{1});
    }
  }
  RunsFromMask(mask, o);
  return o;
}

ChartOutline UnionOutline(const std::vector<ChartFace>& chart,
                          const std::vector<const ChartOutline*>& face_outlines,
                          const std::vector<synth::TrianglePatch>& patches, double t, int gutter) {
  TEXLUME_CHECK(face_outlines.size() == chart.size(), "one outline per face of the chart");
  ChartOutline o = Box(chart, face_outlines.empty() ? 0.0 : face_outlines[0]->angle, patches, t,
                       gutter, nullptr);
  cv::Mat mask = cv::Mat::zeros(o.Height(), o.Width(), CV_8UC1);
  for (const ChartOutline* face : face_outlines) {
    // Both boxes lie on the same integer texel grid: x from lo, rows down from hi.
    const int dx = face->lo.x() - o.lo.x(), dy = o.hi.y() - face->hi.y();
    for (const ChartOutline::Run& r : face->runs) {
      std::uint8_t* row = mask.ptr<std::uint8_t>(r.row + dy) + r.x + dx;
      std::fill(row, row + r.length, std::uint8_t{1});
    }
  }
  RunsFromMask(mask, o);
  return o;
}

double UprightBoxAngle(const std::vector<ChartFace>& chart,
                       const std::vector<synth::TrianglePatch>& patches) {
  std::vector<Eigen::Vector2d> points;
  for (const ChartFace& cf : chart)
    for (const auto& c : patches[static_cast<std::size_t>(cf.face)].corners_in_frame)
      points.push_back(cf.linear * c + cf.translation);
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() != b.x() ? a.x() < b.x() : a.y() < b.y();
  });
  // Monotone chain (Andrew 1979).
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  auto turn_left = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                      const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x() > 0;
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && !turn_left(hull[k - 2], hull[k - 1], points[i])) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && !turn_left(hull[k - 2], hull[k - 1], points[i])) --k;
    hull[k++] = points[i];
  }
  hull.resize(k > 1 ? k - 1 : k);
  double best_area = std::numeric_limits<double>::max(), best_angle = 0.0;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
    if (e.squaredNorm() == 0.0) continue;
    const double angle = -std::atan2(e.y(), e.x());
    const Eigen::Matrix2d r = Eigen::Rotation2Dd(angle).toRotationMatrix();
    Eigen::Vector2d lo = r * hull[0], hi = lo;
    for (const auto& p : hull) lo = lo.cwiseMin(r * p), hi = hi.cwiseMax(r * p);
    const double area = (hi - lo).prod();
    if (area < best_area - 1e-12 * std::abs(best_area)) best_area = area, best_angle = angle;
  }
  return best_angle;
}

OutlineSquare LargestSquare(const ChartOutline& o) {
  const int w = o.Width(), h = o.Height();
  std::vector<char> inside(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  for (const ChartOutline::Run& r : o.runs)
    std::fill_n(inside.begin() + static_cast<std::ptrdiff_t>(r.row) * w + r.x, r.length, 1);
  // side(x, y) = 1 + min(side right, below, right-below) inside, from the bottom-right;
  // ties go to the earlier position (rows up, then columns left).
  std::vector<int> below(static_cast<std::size_t>(w) + 1, 0), here(below.size(), 0);
  OutlineSquare best;
  for (int y = h - 1; y >= 0; --y) {
    const char* row = &inside[static_cast<std::size_t>(y) * static_cast<std::size_t>(w)];
    for (int x = w - 1; x >= 0; --x) {
      const auto i = static_cast<std::size_t>(x);
      here[i] = row[x] ? 1 + std::min({here[i + 1], below[i], below[i + 1]}) : 0;
      if (here[i] > 0 && here[i] >= best.side) best = {y, x, here[i]};
    }
    std::swap(here, below);
  }
  return best;
}

std::vector<std::vector<OutlineSquare>> LargestSquares(
    const std::vector<std::vector<ChartOutline>>& outlines) {
  std::vector<std::vector<OutlineSquare>> cores(outlines.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t c = 0; c < outlines.size(); ++c)
    for (const ChartOutline& o : outlines[c]) cores[c].push_back(LargestSquare(o));
  return cores;
}

namespace {

// An atlas of PackOutlines. Charts come largest first, so an atlas that has refused
// kBinRefusalsToClose charts in a row is passed over until they are half as large as
// the last it refused; then it is tried again, for its holes.
struct OutlineBin {
  explicit OutlineBin(int size) : bin(size) {}
  bool PassedOver(double area) {
    if (closed_at_area > 0.0 && area > 0.5 * closed_at_area) return true;
    closed_at_area = 0.0;
    return false;
  }
  void Refused(double area) {
    if (++refused_in_a_row == kBinRefusalsToClose) closed_at_area = area, refused_in_a_row = 0;
  }
  void Took(const ChartOutline& o, const OutlineDrop& drop) {
    bin.Take(o, drop.x, drop.y);
    refused_in_a_row = 0;
  }
  PackingBin bin;
  int refused_in_a_row = 0;
  double closed_at_area = 0.0;  // 0: open
};

// The chart's drop in `bin` at the turn `rule` prefers (`cores`: each turn's largest
// square); rotation -1: no turn fits.
OutlineDrop BestDrop(const std::vector<ChartOutline>& turns,
                     const std::vector<OutlineSquare>& cores, const PackingBin& bin, int bin_size,
                     DropRule rule) {
  std::vector<std::pair<int, int>> fit(turns.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t r = 0; r < turns.size(); ++r)
    fit[r] = bin.FirstFit(turns[r], cores[r], bin_size);
  const auto key = [&](std::size_t r) {
    const int y = fit[r].second;
    return std::make_tuple(rule == DropRule::kLowestBottom ? y + turns[r].Height() : y,
                           fit[r].first, y);
  };
  int best = -1;
  for (std::size_t r = 0; r < turns.size(); ++r)
    if (fit[r].first >= 0 && (best < 0 || key(r) < key(static_cast<std::size_t>(best))))
      best = static_cast<int>(r);
  if (best < 0) return {0, -1, -1, -1};
  const auto [x, y] = fit[static_cast<std::size_t>(best)];
  return {0, best, x, y};
}

}  // namespace

OutlinePacking PackOutlines(const std::vector<std::vector<ChartOutline>>& outlines,
                            const std::vector<std::vector<OutlineSquare>>& cores,
                            const std::vector<std::size_t>& order, int bin_size, DropRule rule,
                            const std::function<void()>& placed) {
  OutlinePacking packing;
  packing.drops.resize(outlines.size());
  std::vector<OutlineBin> bins;
  for (const std::size_t c : order) {
    const double area = outlines[c].empty() ? 0.0 : outlines[c][0].area;
    for (std::size_t b = 0;; ++b) {
      if (b == bins.size()) bins.emplace_back(bin_size);
      if (bins[b].PassedOver(area)) {
        ++packing.bins_passed_over;
        continue;
      }
      OutlineDrop drop = BestDrop(outlines[c], cores[c], bins[b].bin, bin_size, rule);
      if (drop.rotation < 0) {
        // An empty atlas that refuses it: no atlas ever takes it (CheckOutlinesFit).
        TEXLUME_CHECK(bins[b].bin.UsedRows() > 0, "every chart fits an empty atlas");
        bins[b].Refused(area);
        continue;
      }
      bins[b].Took(outlines[c][static_cast<std::size_t>(drop.rotation)], drop);
      drop.bin = static_cast<int>(b);
      packing.drops[c] = drop;
      break;
    }
    if (placed) placed();
  }
  for (std::size_t b = 0; b < bins.size(); ++b)
    packing.texels += static_cast<std::int64_t>(bin_size) *
                      (b + 1 < bins.size() ? bin_size : bins[b].bin.UsedRows());
  return packing;
}

namespace {

// Where the faces at one end of a band slide to in the current row: the turn (-1: nowhere),
// the outline box's x and its rows below the row's top, and the gap its left end leaves.
struct Slide {
  int turn = -1, x = 0, dy = 0;
  double gap = 0.0;
  ChartOutline outline;
};

// Strip charts packed in rows (RowPacking): the bands are sorted tallest first, then each in
// turn (by best fit in a started row) is placed along the rows, cut where it overruns one.
class RowPacker {
 public:
  RowPacker(const std::vector<synth::TrianglePatch>& patches, double t, int gutter, int atlas_size,
            const ProgressCallback& progress)
      : patches_(patches), t_(t), gutter_(gutter), atlas_size_(atlas_size), progress_(progress) {}

  // Packs the charts and counts the atlas texels used.
  RowPacking Run(const std::vector<std::vector<ChartFace>>& charts);

 private:
  // Band x of a face (texels): the centroid of its corners in the chart frame.
  double BandX(const ChartFace& cf) const;
  // The charts' faces in band order, their heights, and the order they are packed in.
  void SortBands(const std::vector<std::vector<ChartFace>>& charts);
  // Starts a row of height h, in the next atlas when this one is full.
  void NewRow(int h);
  // Where `o` slides to in the current row: the smallest x where no run
  // overlaps the row's used texels.
  int SlideTo(const ChartOutline& o, int dy) const;
  // Texels left empty between the row's right edge and outline `o` slid to
  // x at dy, per row of the outline: the gap its left end leaves.
  double GapPerRow(const ChartOutline& o, int x, int dy) const;
  // Whole chart c's outline at turn 0 or 1 (180 degrees), made when first needed.
  const ChartOutline& WholeOutline(std::size_t c, int turn);
  // A piece's outline at a turn, from its faces' outlines (each made once per chart).
  ChartOutline PieceOutline(std::vector<ChartFace>::iterator first,
                            std::vector<ChartFace>::iterator last, int turn);
  // The position in `order_` of the chart to pack next.
  std::size_t PickChart();
  // Places all of chart c, cut into pieces along the rows.
  void PackChart(std::size_t c);
  // The `count` faces at the front of the band (turn 0, placed from the left)
  // or at its back (turned by 180 degrees, the back comes first).
  std::pair<std::vector<ChartFace>::iterator, std::vector<ChartFace>::iterator> EndOfRest(
      int turn, std::size_t count);
  // The best slide of the `count` faces at the chosen end, over both
  // turns and, for pieces shorter than the row, every height in it.
  Slide BestSlide(std::size_t count);
  // Places the longest prefix of the rest of chart c (in the turned order) that fits the
  // current row; false if none does.
  bool PlacePiece(std::size_t c);
  // The atlas texels used, the last atlas cropped to its used rows.
  void CountTexels();

  const std::vector<synth::TrianglePatch>& patches_;
  const double t_;
  const int gutter_;
  const int atlas_size_;
  const ProgressCallback& progress_;

  std::vector<std::vector<ChartFace>> queue_;
  std::vector<int> height_;  // texels, outline box at turn 0
  std::vector<std::size_t> order_;
  // Whole charts' outlines at 0 and 180 degrees, made when first needed.
  std::vector<std::array<std::optional<ChartOutline>, 2>> whole_;
  std::vector<char> pending_;  // per position in `order_`
  std::size_t first_pending_ = 0;
  std::size_t done_ = 0;

  RowPacking out_;
  int atlas_ = 0, row_y_ = 0, row_height_ = 0;
  std::vector<int> right_edge_;  // per row of the current band row: first free x
  std::vector<ChartFace> rest_;  // faces of the chart being packed not yet placed
  // The outlines of the chart's faces at turn 0 and 1, by face.
  std::array<std::unordered_map<int, ChartOutline>, 2> face_outlines_;
};

RowPacking RowPacker::Run(const std::vector<std::vector<ChartFace>>& charts) {
  SortBands(charts);
  whole_.resize(queue_.size());
  pending_.assign(order_.size(), 1);
  while (done_ < order_.size()) {
    const std::size_t pick = PickChart();
    pending_[pick] = 0;
    PackChart(order_[pick]);
    ++done_;
    if (progress_ && (done_ % 8 == 0 || done_ == order_.size()))
      progress_("packing strips", done_, order_.size());
  }
  CountTexels();
  return std::move(out_);
}

double RowPacker::BandX(const ChartFace& cf) const {
  double x = 0;
  for (const auto& c : patches_[static_cast<std::size_t>(cf.face)].corners_in_frame)
    x += (cf.linear * c + cf.translation).x();
  return x / (3.0 * t_);
}

void RowPacker::SortBands(const std::vector<std::vector<ChartFace>>& charts) {
  for (const auto& chart : charts) {
    std::vector<ChartFace> sorted = chart;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [&](const ChartFace& a, const ChartFace& b) { return BandX(a) < BandX(b); });
    queue_.push_back(std::move(sorted));
    height_.push_back(Box(chart, 0.0, patches_, t_, gutter_, nullptr).Height());
  }
  order_.resize(queue_.size());
  for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = i;
  std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
    return height_[a] != height_[b] ? height_[a] > height_[b] : queue_[a].size() > queue_[b].size();
  });
}

void RowPacker::NewRow(int h) {
  row_y_ += row_height_;
  if (row_y_ + h > atlas_size_) ++atlas_, row_y_ = 0;
  row_height_ = h;
  right_edge_.assign(static_cast<std::size_t>(h), 0);
}

int RowPacker::SlideTo(const ChartOutline& o, int dy) const {
  int x = 0;
  for (const ChartOutline::Run& r : o.runs)
    x = std::max(x, right_edge_[static_cast<std::size_t>(r.row + dy)] - r.x);
  return x;
}

double RowPacker::GapPerRow(const ChartOutline& o, int x, int dy) const {
  double gap = 0.0;
  int rows = 0;
  for (int row = 0; row < o.Height(); ++row) {
    const int first = o.row_first_x[static_cast<std::size_t>(row)];
    if (first == std::numeric_limits<int>::max()) continue;
    gap += x + first - right_edge_[static_cast<std::size_t>(row + dy)];
    ++rows;
  }
  return rows > 0 ? gap / rows : 0.0;
}

ChartOutline RowPacker::PieceOutline(std::vector<ChartFace>::iterator first,
                                     std::vector<ChartFace>::iterator last, int turn) {
  const std::vector<ChartFace> piece(first, last);
  std::vector<const ChartOutline*> faces;
  for (const ChartFace& cf : piece) {
    auto& cached = face_outlines_[static_cast<std::size_t>(turn)];
    auto it = cached.find(cf.face);
    if (it == cached.end())
      it = cached.emplace(cf.face, Outline({cf}, turn * kPi, patches_, t_, gutter_)).first;
    faces.push_back(&it->second);
  }
  return UnionOutline(piece, faces, patches_, t_, gutter_);
}

const ChartOutline& RowPacker::WholeOutline(std::size_t c, int turn) {
  auto& o = whole_[c][static_cast<std::size_t>(turn)];
  if (!o) o = Outline(queue_[c], turn * kPi, patches_, t_, gutter_);
  return *o;
}

std::size_t RowPacker::PickChart() {
  while (!pending_[first_pending_]) ++first_pending_;
  std::size_t pick = first_pending_;
  // Best fit: in a started row, the whole chart (of the next
  // kBestFitCandidates of the row's height) whose left end leaves the least
  // gap, so slanted ends nest instead of leaving triangles empty.
  if (row_height_ > 0 &&
      std::any_of(right_edge_.begin(), right_edge_.end(), [](int e) { return e > 0; })) {
    double best_gap = std::numeric_limits<double>::max();
    int tried = 0;
    for (std::size_t i = first_pending_; i < order_.size() && tried < kBestFitCandidates; ++i) {
      if (!pending_[i] || height_[order_[i]] != row_height_) continue;
      ++tried;
      for (int turn = 0; turn < 2; ++turn) {
        const ChartOutline& o = WholeOutline(order_[i], turn);
        for (int dy = 0; dy + o.Height() <= row_height_; ++dy) {
          const int x = SlideTo(o, dy);
          if (x + o.Width() > atlas_size_) continue;
          const double gap = GapPerRow(o, x, dy);
          if (gap < best_gap) best_gap = gap, pick = i;
        }
      }
    }
  }
  return pick;
}

void RowPacker::PackChart(std::size_t c) {
  if (height_[c] > atlas_size_)
    throw OptionError("a strip chart of " + std::to_string(height_[c]) +
                      " texels' height does not fit an atlas of " + std::to_string(atlas_size_));
  rest_ = queue_[c];
  for (auto& cached : face_outlines_) cached.clear();
  while (!rest_.empty()) {
    if (row_height_ == 0) NewRow(height_[c]);
    if (!PlacePiece(c)) {
      if (std::all_of(right_edge_.begin(), right_edge_.end(), [](int e) { return e == 0; }))
        throw OptionError("a strip chart does not fit an atlas of " + std::to_string(atlas_size_));
      NewRow(height_[c]);
    }
  }
}

std::pair<std::vector<ChartFace>::iterator, std::vector<ChartFace>::iterator> RowPacker::EndOfRest(
    int turn, std::size_t count) {
  const auto n = static_cast<std::ptrdiff_t>(count);
  return turn == 0 ? std::make_pair(rest_.begin(), rest_.begin() + n)
                   : std::make_pair(rest_.end() - n, rest_.end());
}

Slide RowPacker::BestSlide(std::size_t count) {
  Slide best;
  for (int turn = 0; turn < 2; ++turn) {
    const auto [first, last] = EndOfRest(turn, count);
    ChartOutline o = PieceOutline(first, last, turn);
    // Shorter pieces may sit lower in the row, under others.
    for (int dy = 0; dy + o.Height() <= row_height_; ++dy) {
      const int x = SlideTo(o, dy);
      if (x + o.Width() > atlas_size_) continue;
      const double gap = GapPerRow(o, x, dy);
      if (best.turn < 0 || gap < best.gap ||
          (gap == best.gap && x + o.Width() < best.x + best.outline.Width()))
        best = Slide{turn, x, dy, gap, o};
    }
  }
  return best;
}

bool RowPacker::PlacePiece(std::size_t c) {
  // The longest prefix of `rest` (in the turned order) that fits this row.
  if (height_[c] > row_height_) return false;
  std::size_t count = rest_.size();
  Slide best = BestSlide(count);
  if (best.turn < 0) {
    // The most faces that fit, by bisection (fewer faces never fit worse).
    std::size_t fits = 0, fails = count;
    while (fails - fits > 1) {
      const std::size_t mid = fits + (fails - fits) / 2;
      Slide s = BestSlide(mid);
      if (s.turn >= 0) {
        fits = mid;
        best = std::move(s);
      } else {
        fails = mid;
      }
    }
    count = fits;
  }
  if (count == 0 || best.turn < 0) return false;
  const auto [first, last] = EndOfRest(best.turn, count);
  std::vector<ChartFace> piece(first, last);
  rest_.erase(first, last);
  for (const ChartOutline::Run& r : best.outline.runs) {
    int& edge = right_edge_[static_cast<std::size_t>(r.row + best.dy)];
    edge = std::max(edge, best.x + r.x + r.length);
  }
  out_.pieces.push_back(std::move(piece));
  out_.outlines.push_back(std::move(best.outline));
  out_.drops.push_back({atlas_, best.x, row_y_ + best.dy});
  return true;
}

void RowPacker::CountTexels() {
  std::vector<int> used_rows(static_cast<std::size_t>(atlas_) + 1, 0);
  for (std::size_t p = 0; p < out_.pieces.size(); ++p) {
    int& rows = used_rows[static_cast<std::size_t>(out_.drops[p][0])];
    rows = std::max(rows, out_.drops[p][2] + out_.outlines[p].Height());
  }
  for (std::size_t a = 0; a < used_rows.size(); ++a)
    out_.texels += static_cast<std::int64_t>(atlas_size_) *
                   (a + 1 < used_rows.size() ? atlas_size_ : used_rows[a]);
}

}  // namespace

RowPacking PackStripsInRows(const std::vector<std::vector<ChartFace>>& charts,
                            const std::vector<synth::TrianglePatch>& patches, double t, int gutter,
                            int atlas_size, const ProgressCallback& progress) {
  return RowPacker(patches, t, gutter, atlas_size, progress).Run(charts);
}

}  // namespace texlume::atlas::chart_packing
