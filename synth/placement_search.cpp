#include "synth/placement_search.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <unordered_set>

#include "synth/template_match.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {
namespace {

// Density levels are quarter octaves: four levels halve the density.
constexpr int kLevelsPerHalving = 4;
// Coarse to fine only when every placement is at least this many times those refined.
constexpr double kRefineFraction = 4.0;
// Every placement's sum directly when its vector multiply-adds are fewer than this
// many times the FFT's operations (DirectIsCheaper): on s512's coarse grids
// (about 99 x 99 placements of a 10 x 10 mask, 128 x 128 transforms) a vector
// multiply-add took about 2.6 times an FFT operation (perf samples: 3.3 % of the
// job direct against 7.1 % by FFT, for 0.18 times the operations).
constexpr double kDirectPerFftOperation = 0.4;

// Half a cell of `stride` texels, rounded up: how far from a coarse candidate the
// next density's placements are scored.
int HalfCell(int stride) { return (stride + 1) / 2; }

// The best `k` of `scored`, best first.
std::vector<ScoredPlacement> KeepBest(std::vector<ScoredPlacement> scored, int k) {
  const std::size_t kept = std::min<std::size_t>(static_cast<std::size_t>(k), scored.size());
  std::partial_sort(scored.begin(), scored.begin() + static_cast<std::ptrdiff_t>(kept),
                    scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  scored.resize(kept);
  return scored;
}

// Runs view(r) for every r in [0, count) on every core, unless the search itself
// runs on one of several threads (the engine's faces searched ahead). An exception
// must not leave an OpenMP loop: each view's is kept and the first view's rethrown.
template <typename PerView>
void ForEachView(std::size_t count, const PerView& view) {
  std::vector<std::exception_ptr> errors(count);
#pragma omp parallel for schedule(dynamic, 1) if (count > 1 && !omp_in_parallel())
  for (std::size_t r = 0; r < count; ++r) {
    try {
      view(r);
    } catch (...) {
      errors[r] = std::current_exception();
    }
  }
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
}

// kLanes floats side by side: one AVX2 register, or two SSE2 ones on any x86-64.
static_assert(PlacementSearch::kLanes == 8, "a vector of 8 floats (a power of two)");
using PlacementLanes = float __attribute__((vector_size(PlacementSearch::kLanes * sizeof(float))));

// RowOfCellScores' sums of squared differences, before eq. 3's root. Each lane
// (placement) sums as one placement alone would: a row's sum in floats over the
// channels and the row's cells in order, rows in doubles. Inlined into the
// builds below, whose lanes give the same values.
[[gnu::always_inline]] inline void SumSquaredDifferences(
    const cv::Mat& mask, const std::vector<cv::Mat>& photo,
    const std::array<cv::Mat, 3>& relit_planes, cv::Point at,
    std::array<double, PlacementSearch::kLanes>& ssd) {
  for (int j = 0; j < mask.rows; ++j) {
    const float* m = mask.ptr<float>(j);
    PlacementLanes row = {};
    for (std::size_t c = 0; c < photo.size(); ++c) {
      const float* s = relit_planes[c].ptr<float>(at.y + j) + at.x;
      const float* p = photo[c].ptr<float>(j);
      for (int i = 0; i < mask.cols; ++i) {
        PlacementLanes relit_i;  // cell i of each lane's placement
        std::memcpy(&relit_i, s + i, sizeof(PlacementLanes));
        const PlacementLanes d = relit_i - p[i];
        row += m[i] * d * d;
      }
    }
    for (int k = 0; k < PlacementSearch::kLanes; ++k) ssd[static_cast<std::size_t>(k)] += row[k];
  }
}

void SumSquaredDifferencesGeneric(const cv::Mat& mask, const std::vector<cv::Mat>& photo,
                                  const std::array<cv::Mat, 3>& relit_planes, cv::Point at,
                                  std::array<double, PlacementSearch::kLanes>& ssd) {
  SumSquaredDifferences(mask, photo, relit_planes, at, ssd);
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2"))) void SumSquaredDifferencesAvx2(
    const cv::Mat& mask, const std::vector<cv::Mat>& photo,
    const std::array<cv::Mat, 3>& relit_planes, cv::Point at,
    std::array<double, PlacementSearch::kLanes>& ssd) {
  SumSquaredDifferences(mask, photo, relit_planes, at, ssd);
}

bool ScoresUseAvx2() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}
#endif

// SumSquaredDifferences in AVX2 where the CPU has it, else generic (SSE2 on x86-64).
void SumSquaredDifferencesHere(const cv::Mat& mask, const std::vector<cv::Mat>& photo,
                               const std::array<cv::Mat, 3>& relit_planes, cv::Point at,
                               std::array<double, PlacementSearch::kLanes>& ssd) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (ScoresUseAvx2()) return SumSquaredDifferencesAvx2(mask, photo, relit_planes, at, ssd);
#endif
  SumSquaredDifferencesGeneric(mask, photo, relit_planes, at, ssd);
}

// Eq. 3's sums of squares of a view at every placement of its density, directly:
// kLanes placements side by side (SumSquaredDifferences) over its relit sample.
cv::Mat DirectSsd(const cv::Mat& mask, const std::vector<cv::Mat>& photo,
                  const std::vector<cv::Mat>& relit, cv::Size placements) {
  // kLanes - 1 zero columns past the sample: lanes past the last placement read them.
  std::array<cv::Mat, 3> padded;
  for (std::size_t c = 0; c < padded.size(); ++c)
    cv::copyMakeBorder(relit[c], padded[c], 0, 0, 0, PlacementSearch::kLanes - 1,
                       cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat ssd(placements, CV_32FC1);
  for (int y = 0; y < placements.height; ++y)
    for (int x = 0; x < placements.width; x += PlacementSearch::kLanes) {
      std::array<double, PlacementSearch::kLanes> row{};
      SumSquaredDifferencesHere(mask, photo, padded, cv::Point(x, y), row);
      for (int k = 0; k < PlacementSearch::kLanes && x + k < placements.width; ++k)
        ssd.at<float>(y, x + k) = static_cast<float>(row[static_cast<std::size_t>(k)]);
    }
  return ssd;
}

// Whether DirectSsd is the cheaper way to every placement's sum: its multiply-adds
// (each placement's masked cells, per channel, kLanes at once) against the FFT's
// (ImageSpectra: the sample's 3 planes and energy, the photo's 3 and mask, and
// one back, n log2 n each, on the padded size).
bool DirectIsCheaper(cv::Size sample, cv::Size mask, cv::Size placements, std::size_t channels) {
  const double direct =
      static_cast<double>(channels) * placements.area() * mask.area() / PlacementSearch::kLanes;
  const double padded = static_cast<double>(FastDftSize(sample.width)) * FastDftSize(sample.height);
  const double fft = 9.0 * padded * std::log2(padded);
  return direct < kDirectPerFftOperation * fft;
}

}  // namespace

std::array<cv::Mat, 3> RelitScratch::Planes(std::size_t slot, cv::Size size) {
  if (buffers_.size() <= slot) buffers_.resize(slot + 1);
  std::array<cv::Mat, 3> out;
  for (std::size_t c = 0; c < out.size(); ++c) {
    cv::Mat& buffer = buffers_[slot][c];
    if (buffer.cols < size.width || buffer.rows < size.height)
      buffer.create(std::max(buffer.rows, size.height), std::max(buffer.cols, size.width),
                    CV_32FC1);
    out[c] = buffer(cv::Rect(cv::Point(0, 0), size));
  }
  return out;
}

PlacementSearch::PlacementSearch(const MaterialSample& sample,
                                 const std::vector<RectifiedView>& views,
                                 const std::vector<double>& photo_gains, cv::Size patch_texels,
                                 RelitScratch* scratch)
    : sample_(sample),
      views_(views),
      photo_gains_(photo_gains),
      patch_(patch_texels),
      scratch_(scratch) {
  last_x_ = sample.Width() - patch_texels.width;
  last_y_ = sample.Height() - patch_texels.height;
}

cv::Point PlacementSearch::ViewAtStep::Cell(cv::Point texel) const {
  // As AddImageScore reads a placement's score: the nearest cell.
  return {std::min(static_cast<int>(std::lround(texel.x * reduced->rx)), placements_x - 1),
          std::min(static_cast<int>(std::lround(texel.y * reduced->ry)), placements_y - 1)};
}

std::vector<PlacementSearch::ViewAtStep> PlacementSearch::ViewsAtStep(int step) const {
  std::vector<ViewAtStep> out;
  out.reserve(views_.size());
  for (const RectifiedView& r : views_) {
    ViewAtStep& v = out.emplace_back();
    v.view = &r;
    v.reduced = &sample_.Reduced(r.level + kLevelsPerHalving * step);
    if (step == 0) {
      v.photo = r.planes;
      v.mask = r.mask;
      v.count = r.count;
    } else {
      // The photo at the coarser density: the masked mean of the cells each coarse
      // cell covers, weighted by how much of it is seen.
      const cv::Size grid(
          std::max(1, static_cast<int>(std::lround(patch_.width * v.reduced->rx))),
          std::max(1, static_cast<int>(std::lround(patch_.height * v.reduced->ry))));
      cv::resize(r.mask, v.mask, grid, 0, 0, cv::INTER_AREA);
      v.photo.resize(r.planes.size());
      for (std::size_t c = 0; c < r.planes.size(); ++c) {
        cv::Mat weighted;
        cv::resize(r.planes[c].mul(r.mask), weighted, grid, 0, 0, cv::INTER_AREA);
        cv::divide(weighted, v.mask, v.photo[c]);
        v.photo[c].setTo(0.0f, v.mask <= 0.0f);  // 0 / 0 is NaN: 0 where nothing is seen
      }
      v.count = cv::sum(v.mask)[0];
    }
    v.placements_x = v.reduced->planes[0].cols - v.mask.cols + 1;
    v.placements_y = v.reduced->planes[0].rows - v.mask.rows + 1;
  }
  return out;
}

int PlacementSearch::CoarseSteps(int max_steps, int min_cells) const {
  int steps = 0;
  for (int step = 1; step <= max_steps; ++step) {
    bool fits = true;
    for (std::size_t n = 0; n < views_.size() && fits; ++n) {
      const ReducedPlanes& r = sample_.Reduced(views_[n].level + kLevelsPerHalving * step);
      const int gw = std::max(1, static_cast<int>(std::lround(patch_.width * r.rx)));
      const int gh = std::max(1, static_cast<int>(std::lround(patch_.height * r.ry)));
      fits = gw <= r.planes[0].cols && gh <= r.planes[0].rows &&
             (n > 0 || (gw >= min_cells && gh >= min_cells));
    }
    if (!fits) break;
    steps = step;
  }
  return steps;
}

int PlacementSearch::Stride(const std::vector<ViewAtStep>& views) {
  return std::max(1, static_cast<int>(std::floor(1.0 / views.front().reduced->rx)));
}

std::vector<cv::Mat> PlacementSearch::RelitCells(const ViewAtStep& v, cv::Rect cells) const {
  return sample_.Relight(v.reduced->Window(cells), v.view->lighting, photo_gains_[v.view->photo]);
}

std::vector<ScoredPlacement> PlacementSearch::ScoreOnGrid(const std::vector<ViewAtStep>& views,
                                                          int stride) const {
  // Eq. 3 of every view at every placement of its density (FFT or DirectSsd), read
  // at the placements `stride` texels apart, in rows.
  std::vector<ScoredPlacement> scored;
  for (int sy = 0; sy <= last_y_; sy += stride)
    for (int sx = 0; sx <= last_x_; sx += stride) scored.emplace_back(0.0f, cv::Point(sx, sy));
  // The views' relit samples and SSD maps on every core (ForEachView), summed in view order.
  std::vector<cv::Mat> ssd(views.size());
  ForEachView(views.size(), [&](std::size_t r) {
    const ViewAtStep& v = views[r];
    const std::vector<cv::Mat> model =
        sample_.Relight(*v.reduced, v.view->lighting, photo_gains_[v.view->photo]);
    const cv::Size placements(v.placements_x, v.placements_y);
    ssd[r] = DirectIsCheaper(model[0].size(), v.mask.size(), placements, v.photo.size())
                 ? DirectSsd(v.mask, v.photo, model, placements)
                 : ImageSpectra(model, PlaneEnergy(model)).MaskedSsd(v.photo, v.mask);
  });
  for (std::size_t r = 0; r < views.size(); ++r) {
    const ViewAtStep& v = views[r];
    const float cells = static_cast<float>(v.count);
    for (auto& [score, texel] : scored) {
      const cv::Point at = v.Cell(texel);
      score += std::sqrt(ssd[r].at<float>(at.y, at.x) / (3.0f * cells));  // as AddImageScore
    }
  }
  return scored;
}

class PlacementSearch::RelitView {
 public:
  // A view's eq. 3 by placement cell (row-major keys >= 0), as scored so far: open
  // addressing with linear probing, at most half full (a std::unordered_map cost an
  // allocation per score).
  class CellScores {
   public:
    // The score kept for `key`, or null.
    const double* Find(long long key) const {
      if (keys_.empty()) return nullptr;
      for (std::size_t i = Slot(key);; i = (i + 1) & mask_) {
        if (keys_[i] == key) return &values_[i];
        if (keys_[i] < 0) return nullptr;
      }
    }
    // Keeps `score` for `key` unless it has one already.
    void Insert(long long key, double score) {
      if (2 * (size_ + 1) > keys_.size()) Grow();
      std::size_t i = Slot(key);
      for (; keys_[i] >= 0; i = (i + 1) & mask_)
        if (keys_[i] == key) return;
      keys_[i] = key, values_[i] = score, ++size_;
    }

   private:
    // Fibonacci hashing: the product's top bits index the table.
    std::size_t Slot(long long key) const {
      return static_cast<std::size_t>(
          (static_cast<unsigned long long>(key) * 0x9E3779B97F4A7C15ull) >> shift_);
    }
    void Grow() {
      const std::vector<long long> keys = std::move(keys_);
      const std::vector<double> values = std::move(values_);
      const std::size_t capacity = keys.empty() ? 1024 : 2 * keys.size();
      keys_.assign(capacity, -1);
      values_.assign(capacity, 0.0);
      mask_ = capacity - 1;
      shift_ = 64 - std::countr_zero(capacity);
      size_ = 0;
      for (std::size_t i = 0; i < keys.size(); ++i)
        if (keys[i] >= 0) Insert(keys[i], values[i]);
    }
    std::vector<long long> keys_;  // -1: empty
    std::vector<double> values_;
    std::size_t size_ = 0, mask_ = 0;
    int shift_ = 64;
  };

  RelitView(const PlacementSearch& search, const ViewAtStep& view, std::array<cv::Mat, 3> planes)
      : relighter_(search.sample_.RelighterOf(*view.reduced, view.view->lighting,
                                              search.photo_gains_[view.view->photo])),
        planes_(std::move(planes)) {
    // The planes are kLanes - 1 columns wider than the reduced sample: lanes past its
    // last placement read zeros there (their scores are not kept).
    for (cv::Mat& plane : planes_)
      for (int y = 0; y < plane.rows; ++y)
        std::fill_n(plane.ptr<float>(y) + plane.cols - (kLanes - 1), kLanes - 1, 0.0f);
    covered_ = cv::Mat::zeros(view.reduced->planes[0].size(), CV_8UC1);
  }
  // Relights the cells of `cells` that are not relit yet: rows whose uncovered cells
  // span the same columns are relit together, one rectangle each.
  void Cover(cv::Rect cells) {
    cells &= cv::Rect(cv::Point(0, 0), covered_.size());
    for (int j = 0; j < cells.height;) {
      const std::pair<int, int> span = Uncovered(cells, j);
      int end = j + 1;
      while (end < cells.height && Uncovered(cells, end) == span) ++end;
      if (span.first < span.second)
        Relight(cv::Rect(span.first, cells.y + j, span.second - span.first, end - j));
      j = end;
    }
  }
  // The view's eq. 3 by placement cell, as scored so far.
  CellScores& scores() { return scores_; }
  const std::array<cv::Mat, 3>& planes() const { return planes_; }

 private:
  // Row j of `cells`: the columns [first, second) from its first to its last cell not
  // relit yet (empty when all are), widened to whole groups of kColumns columns.
  std::pair<int, int> Uncovered(cv::Rect cells, int j) const {
    const unsigned char* row = covered_.ptr<unsigned char>(cells.y + j);
    const auto n = static_cast<std::size_t>(cells.width);
    const auto* first = static_cast<const unsigned char*>(std::memchr(row + cells.x, 0, n));
    if (!first) return {0, 0};
    int last = cells.x + cells.width - 1;
    while (row[last]) --last;  // stops at `first` at the latest
    const int lo = static_cast<int>(first - row) / kColumns * kColumns;
    const int hi = (last / kColumns + 1) * kColumns;
    return {lo, std::min(hi, covered_.cols)};
  }
  void Relight(cv::Rect area) {
    relighter_->Relight(area, planes_);
    covered_(area).setTo(1);
  }

  // Windows start and end on multiples of this many columns (but at the sample's
  // right edge): the relighting's vectors run over whole rows of 8.
  static constexpr int kColumns = 8;
  std::unique_ptr<WindowRelighter> relighter_;
  std::array<cv::Mat, 3> planes_;
  cv::Mat covered_;  // CV_8UC1: 1 where relit
  CellScores scores_;
};

std::array<double, PlacementSearch::kLanes> PlacementSearch::RowOfCellScores(
    const ViewAtStep& v, cv::Point at, RelitView& relit) const {
  relit.Cover(cv::Rect(at, v.mask.size() + cv::Size(kLanes - 1, 0)));
  std::array<double, kLanes> ssd{};
  SumSquaredDifferencesHere(v.mask, v.photo, relit.planes(), at, ssd);
  // Eq. 3: the RMS difference at the photo's density (as AddImageScore).
  for (double& e : ssd) e = std::sqrt(std::max(e, 0.0) / (3.0 * v.count));
  return ssd;
}

std::vector<float> PlacementSearch::ScoreAt(const std::vector<ViewAtStep>& views,
                                            const std::vector<cv::Point>& texels,
                                            std::vector<RelitView>& relit) const {
  // Each view (its own relit cells) on every core (ForEachView); the scores summed in view order.
  std::vector<std::vector<double>> per_view(views.size(), std::vector<double>(texels.size()));
  ForEachView(views.size(), [&](std::size_t r) {
    const ViewAtStep& v = views[r];
    for (std::size_t n = 0; n < texels.size(); ++n) {
      // Placements in one cell of this view score alike: each cell scored once.
      const cv::Point at = v.Cell(texels[n]);
      RelitView::CellScores& scores = relit[r].scores();
      const long long key = static_cast<long long>(at.y) * v.placements_x + at.x;
      if (const double* known = scores.Find(key)) {
        per_view[r][n] = *known;
        continue;
      }
      // This cell and the next kLanes - 1 in its row.
      const std::array<double, kLanes> row = RowOfCellScores(v, at, relit[r]);
      for (int k = 0; k < kLanes && at.x + k < v.placements_x; ++k) scores.Insert(key + k, row[k]);
      per_view[r][n] = row[0];
    }
  });
  std::vector<double> total(texels.size(), 0.0);
  for (const std::vector<double>& scores : per_view)
    for (std::size_t n = 0; n < texels.size(); ++n) total[n] += scores[n];
  return {total.begin(), total.end()};
}

std::vector<ScoredPlacement> PlacementSearch::Exhaustive(int top_k) const {
  const std::vector<ViewAtStep> views = ViewsAtStep(0);
  // Top-k distinct positions at the best view's density (neighbouring texel
  // positions share one photo-density cell and score alike).
  return KeepBest(ScoreOnGrid(views, Stride(views)), top_k);
}

std::vector<ScoredPlacement> PlacementSearch::CoarseToFine(int top_k, int candidates, int max_steps,
                                                           int min_cells) const {
  const int steps = CoarseSteps(max_steps, min_cells);
  if (steps == 0) return Exhaustive(top_k);
  std::vector<ViewAtStep> views = ViewsAtStep(steps);
  int coarse_stride = Stride(views);
  // Refining scores about (2 half a coarse cell / fine + 1)^2 placements per candidate
  // and step; when that is not well below every placement, the exhaustive search is
  // cheaper.
  const int fine_stride = Stride(ViewsAtStep(0));
  const double per_candidate = std::pow(2.0 * HalfCell(coarse_stride) / fine_stride + 1.0, 2.0);
  const double everywhere = (last_x_ / fine_stride + 1.0) * (last_y_ / fine_stride + 1.0);
  if (everywhere < kRefineFraction * std::max(candidates, top_k) * per_candidate * steps)
    return Exhaustive(top_k);
  std::vector<ScoredPlacement> kept =
      KeepBest(ScoreOnGrid(views, coarse_stride), std::max(candidates, top_k));
  RelitScratch own;  // when none is lent
  RelitScratch& scratch = scratch_ ? *scratch_ : own;
  for (int step = steps - 1; step >= 0; --step) {
    views = ViewsAtStep(step);
    const int stride = Stride(views);
    std::vector<RelitView> relit;
    relit.reserve(views.size());
    for (std::size_t r = 0; r < views.size(); ++r)
      relit.emplace_back(
          *this, views[r],
          scratch.Planes(r, views[r].reduced->planes[0].size() + cv::Size(kLanes - 1, 0)));
    // Every placement of this density's grid within half a coarse cell of a candidate
    // (the coarse grid's placements are a coarse cell apart: half a cell reaches
    // every placement nearer to this candidate than to its grid neighbours).
    std::unordered_set<long long> seen;
    std::vector<ScoredPlacement> scored;
    for (const auto& [score, c] : kept) {
      std::vector<cv::Point> near;
      const int reach = HalfCell(coarse_stride);
      const auto first = [&](int v) { return std::max(0, (v - reach + stride - 1) / stride); };
      for (int y = first(c.y) * stride; y <= std::min(last_y_, c.y + reach); y += stride)
        for (int x = first(c.x) * stride; x <= std::min(last_x_, c.x + reach); x += stride)
          if (seen.insert(static_cast<long long>(y) * (last_x_ + 1) + x).second)
            near.emplace_back(x, y);
      if (near.empty()) continue;
      const std::vector<float> s = ScoreAt(views, near, relit);
      for (std::size_t n = 0; n < near.size(); ++n) scored.emplace_back(s[n], near[n]);
    }
    kept = KeepBest(std::move(scored), step == 0 ? top_k : std::max(candidates, top_k));
    coarse_stride = stride;
  }
  return kept;
}

std::vector<RelitWindow> PlacementSearch::RelitAround(cv::Point at,
                                                      const std::vector<int>& margin_cells) const {
  std::vector<RelitWindow> out;
  const std::vector<ViewAtStep> views = ViewsAtStep(0);
  for (std::size_t n = 0; n < views.size(); ++n) {
    const ViewAtStep& v = views[n];
    const int m = margin_cells[n];
    const cv::Rect cells =
        cv::Rect(v.Cell(at) - cv::Point(m, m), v.mask.size() + cv::Size(2 * m, 2 * m)) &
        cv::Rect(0, 0, v.reduced->planes[0].cols, v.reduced->planes[0].rows);
    out.push_back(RelitWindow{RelitCells(v, cells), cells.tl()});
  }
  return out;
}

}  // namespace texlume::synth
