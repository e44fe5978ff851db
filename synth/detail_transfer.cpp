#include "synth/detail_transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "ptm/coefficient_space.h"

namespace texlume::synth {
namespace {

// Detail transfer: a window of 3 x 3 points (dx, dy) texels apart around
// (x, y), 6 orthonormal luminance coefficients each (5 x 5 matched worse on the
// demo: SSIM 0.536 against 0.538).
constexpr int kDetailWindowRadius = 1;
constexpr int kDetailWindowLength =
    (2 * kDetailWindowRadius + 1) * (2 * kDetailWindowRadius + 1) * 6;
// At most this many sample points per dictionary (2^16 windows take 14 MiB;
// a 256 x 256 sample has about 62 000).
constexpr std::size_t kDetailMaxPoints = std::size_t{1} << 16;

// The coarse coefficients of the window of 3 x 3 points (dx, dy) texels apart
// around (x, y), point by point, 6 each: visit(k, value) for k = 0, 1, ... until
// it returns false.
template <typename Visit>
void VisitCoarseWindow(const cv::Mat& coarse, double x, double y, double dx, double dy,
                       Visit visit) {
  std::array<double, 6> at_point;
  int k = 0;
  for (int b = -kDetailWindowRadius; b <= kDetailWindowRadius; ++b)
    for (int a = -kDetailWindowRadius; a <= kDetailWindowRadius; ++a) {
      BilinearTaps(coarse.size(), x + a * dx, y + b * dy).OfChannels(coarse, at_point);
      for (const double v : at_point)
        if (!visit(k++, static_cast<float>(v))) return;
    }
}

void CoarseWindow(const cv::Mat& coarse, double x, double y, double dx, double dy, float* window) {
  VisitCoarseWindow(coarse, x, y, dx, dy, [&](int k, float v) {
    window[k] = v;
    return true;
  });
}

// The squared distance from `query` to the coarse window at (x, y), or a partial
// sum of it of at least `bound` (the sum only grows: the comparison with the bound
// is the same).
double CoarseWindowDistance(const cv::Mat& coarse, double x, double y, double dx, double dy,
                            const float* query, double bound) {
  double e = 0.0;
  VisitCoarseWindow(coarse, x, y, dx, dy, [&](int k, float v) {
    e += (v - query[k]) * (v - query[k]);
    return e < bound;
  });
  return e;
}

}  // namespace

DetailDictionary::DetailDictionary(const PtmSample& sample, int level, std::vector<cv::Mat>& band) {
  const ReducedPlanes& red = sample.Reduced(level);
  dx_ = 1.0 / red.rx, dy_ = 1.0 / red.ry;
  const cv::Size full(sample.Width(), sample.Height());
  // The raw coefficients and LRGB colour (Values()' planes), not a horizon's.
  std::vector<cv::Mat> coarse_raw(sample.Values().size());
  for (std::size_t c = 0; c < coarse_raw.size(); ++c)
    cv::resize(red.planes[c], coarse_raw[c], full, 0, 0, cv::INTER_LINEAR);
  const Eigen::Matrix<double, 6, 6>& to = ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
  coarse_ = cv::Mat(full, CV_32FC(6));
  for (int y = 0; y < full.height; ++y)
    for (int x = 0; x < full.width; ++x)
      for (int m = 0; m < 6; ++m) {
        double v = 0.0;
        for (int k = 0; k < 6; ++k)
          v += to(m, k) * coarse_raw[static_cast<std::size_t>(k)].at<float>(y, x);
        coarse_.ptr<float>(y)[x * 6 + m] = static_cast<float>(v);
      }
  const std::vector<cv::Mat>& values = sample.Values();
  band.resize(values.size());
  cv::Mat coarse_plane;
  for (std::size_t c = 0; c < band.size(); ++c) {
    if (c < 6) cv::extractChannel(coarse_, coarse_plane, static_cast<int>(c));
    band[c] = values[c] - (c < 6 ? coarse_plane : coarse_raw[c]);
  }
  IndexWindows(full);
}

void DetailDictionary::IndexWindows(cv::Size full) {
  const int bx = static_cast<int>(std::ceil(kDetailWindowRadius * dx_)),
            by = static_cast<int>(std::ceil(kDetailWindowRadius * dy_));
  const int nx = full.width - 2 * bx, ny = full.height - 2 * by;
  if (nx < 4 || ny < 4) return;  // windows wider than the sample: no transfer
  // Large samples: points on a coarser grid, so a dictionary stays under
  // kDetailMaxPoints windows.
  const int stride = static_cast<int>(
      std::ceil(std::sqrt(static_cast<double>(nx) * ny / static_cast<double>(kDetailMaxPoints))));
  for (int y = by; y < full.height - by; y += stride)
    for (int x = bx; x < full.width - bx; x += stride) points_.emplace_back(x, y);
  cv::Mat windows(static_cast<int>(points_.size()), kDetailWindowLength, CV_32FC1);
  for (std::size_t n = 0; n < points_.size(); ++n)
    CoarseWindow(coarse_, points_[n].x, points_[n].y, dx_, dy_,
                 windows.ptr<float>(static_cast<int>(n)));
  nearest_ = std::make_unique<NearestWindows>(std::move(windows), NearestWindows::Options{});
}

cv::Mat DetailDictionary::CorrectedWindows(const TrianglePatch& patch) const {
  // The coarse coefficients under each cell plus the cell's correction.
  const int gw = patch.correction[0].cols, gh = patch.correction[0].rows;
  std::vector<cv::Mat> corrected(6);
  for (cv::Mat& m : corrected) m = cv::Mat(gh, gw, CV_32FC1);
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      std::array<double, 6> coarse;
      BilinearTaps(coarse_.size(), patch.sample_x + (i + 0.5) * dx_ - 0.5,
                   patch.sample_y + (j + 0.5) * dy_ - 0.5)
          .OfChannels(coarse_, coarse);
      for (std::size_t m = 0; m < 6; ++m)
        corrected[m].at<float>(j, i) =
            static_cast<float>(coarse[m] + patch.correction[m].at<float>(j, i));
    }
  // Each cell's window of them (clamped at the grid's edges).
  cv::Mat windows(gh * gw, kDetailWindowLength, CV_32FC1);
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      float* q = windows.ptr<float>(j * gw + i);
      for (int b = -kDetailWindowRadius; b <= kDetailWindowRadius; ++b)
        for (int a = -kDetailWindowRadius; a <= kDetailWindowRadius; ++a)
          for (std::size_t m = 0; m < 6; ++m)
            *q++ =
                corrected[m].at<float>(std::clamp(j + b, 0, gh - 1), std::clamp(i + a, 0, gw - 1));
    }
  return windows;
}

void DetailDictionary::MatchByIndex(const cv::Mat& windows, const std::vector<int>& cells,
                                    Matches& matches) const {
  if (cells.empty()) return;
  cv::Mat queries(static_cast<int>(cells.size()), kDetailWindowLength, CV_32FC1);
  for (std::size_t n = 0; n < cells.size(); ++n)
    windows.row(cells[n]).copyTo(queries.row(static_cast<int>(n)));
  std::vector<int> indices;
  std::vector<float> distances;
  nearest_->Nearest(queries, indices, distances);
  for (std::size_t n = 0; n < cells.size(); ++n) {
    const cv::Point p = points_[static_cast<std::size_t>(indices[n])];
    const auto c = static_cast<std::size_t>(cells[n]);
    matches.source[c] = cv::Vec2f(static_cast<float>(p.x), static_cast<float>(p.y));
    matches.distance[c] = distances[n];
  }
}

void DetailDictionary::Propagate(const cv::Mat& windows, bool forward, Matches& matches) const {
  // A neighbour cell's match moved by one cell, wherever it is nearer.
  const int gw = matches.width, gh = static_cast<int>(matches.source.size()) / gw;
  const double x_lo = kDetailWindowRadius * dx_, x_hi = coarse_.cols - 1 - x_lo;
  const double y_lo = kDetailWindowRadius * dy_, y_hi = coarse_.rows - 1 - y_lo;
  const auto try_shift = [&](int i, int j, int ni, int nj) {
    if (ni < 0 || nj < 0 || ni >= gw || nj >= gh) return;
    const auto c = static_cast<std::size_t>(j * gw + i), n = static_cast<std::size_t>(nj * gw + ni);
    if (!matches.Found(n)) return;
    const double x = matches.source[n][0] + (i - ni) * dx_;
    const double y = matches.source[n][1] + (j - nj) * dy_;
    if (x < x_lo || x > x_hi || y < y_lo || y > y_hi) return;
    const double e = CoarseWindowDistance(coarse_, x, y, dx_, dy_, windows.ptr<float>(j * gw + i),
                                          matches.distance[c]);
    if (e < matches.distance[c])
      matches.distance[c] = static_cast<float>(e),
      matches.source[c] = cv::Vec2f(static_cast<float>(x), static_cast<float>(y));
  };
  if (forward) {
    for (int j = 0; j < gh; ++j)
      for (int i = 0; i < gw; ++i) try_shift(i, j, i - 1, j), try_shift(i, j, i, j - 1);
  } else {
    for (int j = gh - 1; j >= 0; --j)
      for (int i = gw - 1; i >= 0; --i) try_shift(i, j, i + 1, j), try_shift(i, j, i, j + 1);
  }
}

void DetailDictionary::Transfer(TrianglePatch& patch, int level) const {
  const int gw = patch.correction[0].cols, gh = patch.correction[0].rows;
  TEXLUME_CHECK(gw > 0 && gh > 0, "detail transfer needs a correction grid");
  const cv::Mat windows = CorrectedWindows(patch);
  Matches matches(gw, gh);
  // The index is asked at the cells of one colour of a checkerboard (issue 33:
  // half the queries); the others take their neighbours' matches moved by one
  // cell, and any cell those cannot reach (the sample's edge) asks the index itself.
  std::vector<int> cells;
  for (int j = 0; j < gh; ++j)
    for (int i = j % 2; i < gw; i += 2) cells.push_back(j * gw + i);
  MatchByIndex(windows, cells, matches);
  Propagate(windows, true, matches);
  cells.clear();
  for (int c = 0; c < gw * gh; ++c)
    if (!matches.Found(static_cast<std::size_t>(c))) cells.push_back(c);
  // Coherent matches keep the detail whole where their bands are blended (a
  // second forward pass changes nothing unless the index matched more cells).
  if (!cells.empty()) {
    MatchByIndex(windows, cells, matches);
    Propagate(windows, true, matches);
  }
  Propagate(windows, false, matches);
  patch.detail_source = cv::Mat(gh, gw, CV_32FC2);
  for (int c = 0; c < gw * gh; ++c)
    patch.detail_source.at<cv::Vec2f>(c / gw, c % gw) = matches.source[static_cast<std::size_t>(c)];
  patch.detail_level = level;
}

}  // namespace texlume::synth
