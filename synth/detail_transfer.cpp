#include "synth/detail_transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "mesh/triangle_frame.h"
#include "ptm/coefficient_space.h"

namespace texlume::synth {
namespace {

// Detail transfer: a window of 3 x 3 points (dx, dy) texels apart around
// (x, y), 6 orthonormal luminance coefficients each (5 x 5 matched worse on the
// demo: SSIM 0.536 against 0.538).
constexpr int kDetailWindowRadius = 1;
constexpr int kDetailWindowSide = 2 * kDetailWindowRadius + 1;
constexpr int kCoefficients = 6;
// A point's coefficients padded to 8 floats (two SSE vectors: the window
// distance's loops vectorise); the pads are 0 in the sample's planes and in
// every window.
constexpr int kPointFloats = 8;
constexpr int kDetailWindowLength = kDetailWindowSide * kDetailWindowSide * kPointFloats;
// At most this many sample points per dictionary (a 256 x 256 sample has about
// 62 000; the index holds their 8 principal components, 2 MiB).
constexpr std::size_t kDetailMaxPoints = std::size_t{1} << 16;

// Bilinear taps along one axis of the coarse planes (the sample reduced to the
// photo's density: a pixel is a photo cell) at the window's points centre + k,
// k = -radius..radius, in their pixels (clamped as BilinearTaps clamps).
struct WindowAxis {
  WindowAxis(int size, double centre) {
    for (int k = 0; k < kDetailWindowSide; ++k) {
      const double t = std::clamp(centre + (k - kDetailWindowRadius), 0.0, size - 1.0);
      lo[k] = std::min(static_cast<int>(t), std::max(size - 2, 0));
      hi[k] = std::min(lo[k] + 1, size - 1);
      f[k] = static_cast<float>(t - lo[k]);
    }
  }
  int lo[kDetailWindowSide], hi[kDetailWindowSide];
  float f[kDetailWindowSide];
};

// The orthonormal basis's transform as a row-major array (ToOrthonormal reads it
// row by row).
using OrthonormalTransform = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;

// The raw luminance coefficients at x of the rows `raw` (the first kCoefficients)
// in the orthonormal basis, into `out`.
void ToOrthonormal(const OrthonormalTransform& to, const float* const* raw, int x, float* out) {
  for (int m = 0; m < kCoefficients; ++m) {
    double v = 0.0;
    for (int k = 0; k < kCoefficients; ++k) v += to(m, k) * raw[k][x];
    out[m] = static_cast<float>(v);
  }
}

// Whether cell c (row-major) is to be matched: marked in `wanted`, or every cell
// when it is empty.
bool IsWanted(const cv::Mat& wanted, std::size_t c) {
  return wanted.empty() || wanted.data[c] != 0;
}

// Four floats in one SSE register (GCC's vector extension); a point is two.
using WindowLanes = float __attribute__((vector_size(16)));
constexpr int kLanesPerPoint = kPointFloats / 4;
WindowLanes LoadWindowLanes(const float* p) {
  WindowLanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The coarse coefficients (kPointFloats per point, CV_32FC(kPointFloats) planes at
// the photo's density) of the window of 3 x 3 points one photo cell apart around
// (u, v) (the planes' pixels), bilinear in floats: visit(k, point) for points
// k = 0, 1, ... (kLanesPerPoint lanes each) until it returns false.
template <typename Visit>
void VisitCoarseWindow(const cv::Mat& coarse, cv::Point2d at, Visit visit) {
  const WindowAxis along_x(coarse.cols, at.x), along_y(coarse.rows, at.y);
  WindowLanes point[kLanesPerPoint];
  int k = 0;
  for (int b = 0; b < kDetailWindowSide; ++b) {
    const float* r0 = coarse.ptr<float>(along_y.lo[b]);
    const float* r1 = coarse.ptr<float>(along_y.hi[b]);
    const float fy = along_y.f[b];
    for (int a = 0; a < kDetailWindowSide; ++a) {
      const float fx = along_x.f[a];
      const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy,
                  w11 = fx * fy;
      const float* v00 = r0 + along_x.lo[a] * kPointFloats;
      const float* v10 = r0 + along_x.hi[a] * kPointFloats;
      const float* v01 = r1 + along_x.lo[a] * kPointFloats;
      const float* v11 = r1 + along_x.hi[a] * kPointFloats;
      for (int h = 0; h < kLanesPerPoint; ++h)
        point[h] = w00 * LoadWindowLanes(v00 + 4 * h) + w10 * LoadWindowLanes(v10 + 4 * h) +
                   w01 * LoadWindowLanes(v01 + 4 * h) + w11 * LoadWindowLanes(v11 + 4 * h);
      if (!visit(k++, point)) return;
    }
  }
}

void CoarseWindow(const cv::Mat& coarse, cv::Point2d at, float* window) {
  VisitCoarseWindow(coarse, at, [&](int k, const WindowLanes* point) {
    std::memcpy(window + k * kPointFloats, point, kPointFloats * sizeof(float));
    return true;
  });
}

// The squared distance from `query` to the coarse window at `at` (the planes'
// pixels), or a partial sum of it (whole points) of at least `bound` (the sum only
// grows: the comparison with the bound is the same).
float CoarseWindowDistance(const cv::Mat& coarse, cv::Point2d at, const float* query, float bound) {
  float e = 0.0f;
  VisitCoarseWindow(coarse, at, [&](int k, const WindowLanes* point) {
    WindowLanes squares = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int h = 0; h < kLanesPerPoint; ++h) {
      const WindowLanes d = point[h] - LoadWindowLanes(query + k * kPointFloats + 4 * h);
      squares += d * d;
    }
    e += (squares[0] + squares[1]) + (squares[2] + squares[3]);
    return e < bound;
  });
  return e;
}

}  // namespace

class DetailDictionary::PointWindows : public NearestWindows::Windows {
 public:
  explicit PointWindows(const DetailDictionary& d) : d_(d) {}
  int Count() const override { return static_cast<int>(d_.points_.size()); }
  int Length() const override { return kDetailWindowLength; }
  void Rows(int first, cv::Mat& block) const override {
    for (int r = 0; r < block.rows; ++r) {
      const cv::Point p = d_.points_[static_cast<std::size_t>(first + r)];
      CoarseWindow(d_.coarse_, d_.OnCoarse(p.x, p.y), block.ptr<float>(r));
    }
  }
  float SquaredDistance(const float* query, int window, float bound) const override {
    const cv::Point p = d_.points_[static_cast<std::size_t>(window)];
    return CoarseWindowDistance(d_.coarse_, d_.OnCoarse(p.x, p.y), query, bound);
  }

 private:
  const DetailDictionary& d_;
};

DetailDictionary::~DetailDictionary() = default;

DetailDictionary::DetailDictionary(const PtmSample& sample, int level, cv::Mat& band) {
  const ReducedPlanes& red = sample.Reduced(level);
  rx_ = red.rx, ry_ = red.ry;
  dx_ = 1.0 / red.rx, dy_ = 1.0 / red.ry;
  full_ = cv::Size(sample.Width(), sample.Height());
  coarse_ = ToOrthonormalPoints(red.planes);
  // The raw coefficients and LRGB colour (Values()' planes), not a horizon's, brought
  // back to full size for the band.
  std::vector<cv::Mat> coarse_raw(sample.Values().size());
  for (std::size_t c = 0; c < coarse_raw.size(); ++c)
    cv::resize(red.planes[c], coarse_raw[c], full_, 0, 0, cv::INTER_LINEAR);
  DetailBand(sample.Values(), coarse_raw, band);
  IndexWindows();
}

void DetailDictionary::DetailBand(const std::vector<cv::Mat>& values,
                                  const std::vector<cv::Mat>& coarse_raw, cv::Mat& band) {
  // Each plane minus its coarse version: the luminance coefficients' in the
  // orthonormal basis, the colour planes' as they are; interleaved.
  const OrthonormalTransform to = ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
  const int n = static_cast<int>(values.size());
  band.create(coarse_raw[0].size(), CV_32FC(n));
  std::vector<const float*> value(values.size()), raw(values.size());
  float coarse[kCoefficients];
  for (int y = 0; y < band.rows; ++y) {
    for (std::size_t c = 0; c < values.size(); ++c)
      value[c] = values[c].ptr<float>(y), raw[c] = coarse_raw[c].ptr<float>(y);
    float* texel = band.ptr<float>(y);
    for (int x = 0; x < band.cols; ++x, texel += n) {
      ToOrthonormal(to, raw.data(), x, coarse);
      for (int c = 0; c < kCoefficients; ++c)
        texel[c] = value[static_cast<std::size_t>(c)][x] - coarse[c];
      for (int c = kCoefficients; c < n; ++c)
        texel[c] = value[static_cast<std::size_t>(c)][x] - raw[static_cast<std::size_t>(c)][x];
    }
  }
}

cv::Mat DetailDictionary::ToOrthonormalPoints(const std::vector<cv::Mat>& raw_planes) {
  const OrthonormalTransform to = ptm::OrthonormalBasis::Hemisphere().ToOrthonormal();
  cv::Mat points(raw_planes[0].size(), CV_32FC(kPointFloats));
  std::array<const float*, kCoefficients> raw{};
  for (int y = 0; y < points.rows; ++y) {
    for (std::size_t k = 0; k < raw.size(); ++k) raw[k] = raw_planes[k].ptr<float>(y);
    float* point = points.ptr<float>(y);
    for (int x = 0; x < points.cols; ++x, point += kPointFloats) {
      ToOrthonormal(to, raw.data(), x, point);
      std::fill(point + kCoefficients, point + kPointFloats, 0.0f);  // the pads
    }
  }
  return points;
}

void DetailDictionary::IndexWindows() {
  const cv::Size full = full_;
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
  windows_ = std::make_unique<PointWindows>(*this);
  nearest_ = std::make_unique<NearestWindows>(*windows_, NearestWindows::Options{});
}

cv::Mat DetailDictionary::CorrectedWindows(const TrianglePatch& patch) const {
  // The coarse coefficients under each cell plus the cell's correction.
  const int gw = patch.correction[0].cols, gh = patch.correction[0].rows;
  cv::Mat corrected = cv::Mat::zeros(gh, gw, CV_32FC(kPointFloats));
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      std::array<double, kPointFloats> coarse;
      const cv::Point2d own = CellInSample(patch, i, j), at = OnCoarse(own.x, own.y);
      BilinearTaps(coarse_.size(), at.x, at.y).OfChannels(coarse_, coarse);
      float* point = corrected.ptr<float>(j) + i * kPointFloats;
      for (std::size_t m = 0; m < kCoefficients; ++m)
        point[m] = static_cast<float>(coarse[m] + patch.correction[m].at<float>(j, i));
    }
  // Each cell's window of them (clamped at the grid's edges).
  cv::Mat windows(gh * gw, kDetailWindowLength, CV_32FC1);
  for (int j = 0; j < gh; ++j)
    for (int i = 0; i < gw; ++i) {
      float* q = windows.ptr<float>(j * gw + i);
      for (int b = -kDetailWindowRadius; b <= kDetailWindowRadius; ++b)
        for (int a = -kDetailWindowRadius; a <= kDetailWindowRadius; ++a) {
          const float* point = corrected.ptr<float>(std::clamp(j + b, 0, gh - 1)) +
                               std::clamp(i + a, 0, gw - 1) * kPointFloats;
          q = std::copy(point, point + kPointFloats, q);
        }
    }
  return windows;
}

void DetailDictionary::MatchByIndex(const cv::Mat& windows, const std::vector<int>& cells,
                                    Matches& matches) const {
  if (cells.empty()) return;
  cv::Mat queries(static_cast<int>(cells.size()), kDetailWindowLength, CV_32FC1);
  for (std::size_t n = 0; n < cells.size(); ++n)
    std::memcpy(queries.ptr<float>(static_cast<int>(n)), windows.ptr<float>(cells[n]),
                sizeof(float) * kDetailWindowLength);
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

void DetailDictionary::Propagate(const cv::Mat& windows, bool forward, const cv::Mat& wanted,
                                 Matches& matches) const {
  // A neighbour cell's match moved by one cell, wherever it is nearer.
  const int gw = matches.width, gh = static_cast<int>(matches.source.size()) / gw;
  const double x_lo = kDetailWindowRadius * dx_, x_hi = full_.width - 1 - x_lo;
  const double y_lo = kDetailWindowRadius * dy_, y_hi = full_.height - 1 - y_lo;
  const auto try_shift = [&](int i, int j, int ni, int nj) {
    if (ni < 0 || nj < 0 || ni >= gw || nj >= gh) return;
    const auto c = static_cast<std::size_t>(j * gw + i), n = static_cast<std::size_t>(nj * gw + ni);
    if (!matches.Found(n) || !IsWanted(wanted, c)) return;
    const double x = matches.source[n][0] + (i - ni) * dx_;
    const double y = matches.source[n][1] + (j - nj) * dy_;
    if (x < x_lo || x > x_hi || y < y_lo || y > y_hi) return;
    const float e = CoarseWindowDistance(coarse_, OnCoarse(x, y), windows.ptr<float>(j * gw + i),
                                         matches.distance[c]);
    if (e < matches.distance[c])
      matches.distance[c] = e,
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

void DetailDictionary::Transfer(TrianglePatch& patch, int level, const cv::Mat& wanted) const {
  const int gw = patch.correction[0].cols, gh = patch.correction[0].rows;
  TEXLUME_CHECK(gw > 0 && gh > 0, "detail transfer needs a correction grid");
  TEXLUME_CHECK(wanted.empty() || (wanted.cols == gw && wanted.rows == gh),
                "detail transfer's wanted cells on the correction grid");
  const cv::Mat windows = CorrectedWindows(patch);
  Matches matches(gw, gh);
  // The index is asked at the cells of one colour of a checkerboard (issue 33:
  // half the queries); the others take their neighbours' matches moved by one
  // cell, and any cell those cannot reach (the sample's edge) asks the index itself.
  std::vector<int> cells;
  for (int j = 0; j < gh; ++j)
    for (int i = j % 2; i < gw; i += 2)
      if (IsWanted(wanted, static_cast<std::size_t>(j * gw + i))) cells.push_back(j * gw + i);
  MatchByIndex(windows, cells, matches);
  Propagate(windows, true, wanted, matches);
  cells.clear();
  for (int c = 0; c < gw * gh; ++c)
    if (IsWanted(wanted, static_cast<std::size_t>(c)) &&
        !matches.Found(static_cast<std::size_t>(c)))
      cells.push_back(c);
  // Coherent matches keep the detail whole where their bands are blended (a
  // second forward pass changes nothing unless the index matched more cells).
  if (!cells.empty()) {
    MatchByIndex(windows, cells, matches);
    Propagate(windows, true, wanted, matches);
  }
  Propagate(windows, false, wanted, matches);
  // A cell no read takes keeps its own place in the sample.
  patch.detail_source = cv::Mat(gh, gw, CV_32FC2);
  for (int c = 0; c < gw * gh; ++c) {
    const cv::Point2d own = CellInSample(patch, c % gw, c / gw);
    patch.detail_source.at<cv::Vec2f>(c / gw, c % gw) =
        matches.Found(static_cast<std::size_t>(c))
            ? matches.source[static_cast<std::size_t>(c)]
            : cv::Vec2f(static_cast<float>(own.x), static_cast<float>(own.y));
  }
  patch.detail_level = level;
}

cv::Mat CellsReadWithin(const TrianglePatch& patch, double texel_size, double reach_texels) {
  if (reach_texels < 0.0) return {};
  // The triangle in the patch's texels, centres at integers (as SamplePtmPatch reads).
  std::array<Eigen::Vector2d, 3> corners;
  for (std::size_t k = 0; k < corners.size(); ++k)
    corners[k] = Eigen::Vector2d((patch.corners_in_frame[k].x() - patch.x_min) / texel_size - 0.5,
                                 (patch.y_max - patch.corners_in_frame[k].y()) / texel_size - 0.5);
  // A texel reads the cells whose centres lie within a cell of it along each axis;
  // half a cell more covers the grid's clamped edges.
  const double rx = patch.correction_density.x(), ry = patch.correction_density.y();
  const double reach = reach_texels + std::hypot(1.5 / rx, 1.5 / ry);
  const cv::Size grid = patch.correction[0].size();
  cv::Mat wanted(grid, CV_8UC1);
  for (int j = 0; j < grid.height; ++j)
    for (int i = 0; i < grid.width; ++i) {
      const Eigen::Vector2d centre((i + 0.5) / rx - 0.5, (j + 0.5) / ry - 0.5);
      wanted.at<std::uint8_t>(j, i) = mesh::WithinReachOfTriangle(corners, centre, reach) ? 1 : 0;
    }
  return wanted;
}

}  // namespace texlume::synth
