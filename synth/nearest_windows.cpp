#include "synth/nearest_windows.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <nanoflann.hpp>
#include <stdexcept>

namespace texlume::synth {
namespace {

// The principal components are estimated on at most this many windows.
constexpr int kMaxComponentRows = 8192;
// Rows projected at a time.
constexpr int kProjectedBlockRows = 4096;
// Points per leaf of the kd-tree.
constexpr int kLeafSize = 16;

// nanoflann's search settings with `eps` (renamed in 1.5).
#if NANOFLANN_VERSION >= 0x150
nanoflann::SearchParameters SearchEps(float eps) { return nanoflann::SearchParameters(eps); }
#else
nanoflann::SearchParams SearchEps(float eps) { return nanoflann::SearchParams(0, eps); }
#endif

// The mean (1 x length, CV_32F) and the `count` leading principal directions
// (rows, CV_32F, by decreasing variance), from every step-th window.
void PrincipalComponents(const NearestWindows::Windows& windows, int count, cv::Mat& mean,
                         cv::Mat& directions) {
  const int step = std::max(1, (windows.Count() + kMaxComponentRows - 1) / kMaxComponentRows);
  cv::Mat rows((windows.Count() + step - 1) / step, windows.Length(), CV_32FC1);
  for (int r = 0; r < windows.Count(); r += step) {
    cv::Mat row = rows.row(r / step);
    windows.Rows(r, row);
    CV_DbgAssert(row.data == rows.ptr(r / step));  // written in place
  }
  cv::Mat covariance, mean64, variances, all;
  cv::calcCovarMatrix(rows, covariance, mean64, cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_SCALE,
                      CV_64F);
  cv::eigen(covariance, variances, all);  // descending, symmetric
  mean64.convertTo(mean, CV_32F);
  all.rowRange(0, count).convertTo(directions, CV_32F);
}

}  // namespace

// nanoflann's dataset adaptor over the projected windows (a row each, contiguous).
struct NearestWindows::Tree {
  cv::Mat projected;
  const float* points = nullptr;  // projected's rows
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(projected.rows); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const {
    return points[i * NearestWindows::kComponents + d];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Tree>, Tree,
                                                    NearestWindows::kComponents, std::uint32_t>;
  std::unique_ptr<Index> index;
  std::vector<std::uint32_t> window_of_point;  // the window each point (row of projected) is

  // The tree's order of the points (its leaves' points side by side).
  std::vector<std::uint32_t>& Order() {
#if NANOFLANN_VERSION >= 0x150
    return index->vAcc_;
#else
    return index->vAcc;
#endif
  }

  // Stores the points in the tree's order, so that a leaf's points lie side by
  // side in memory (issue 33: the leaves' scans read scattered rows and missed
  // the cache); the tree then visits them in the same order as before.
  void StoreInTreeOrder() {
    std::vector<std::uint32_t>& order = Order();
    cv::Mat sorted(projected.rows, projected.cols, CV_32FC1);
    for (std::size_t n = 0; n < order.size(); ++n)
      std::memcpy(sorted.ptr<float>(static_cast<int>(n)),
                  projected.ptr<float>(static_cast<int>(order[n])), sizeof(float) * kComponents);
    window_of_point = order;
    for (std::size_t n = 0; n < order.size(); ++n) order[n] = static_cast<std::uint32_t>(n);
    projected = sorted;
    points = projected.ptr<float>();
  }
};

NearestWindows::WindowMatrix::WindowMatrix(cv::Mat windows) : windows_(std::move(windows)) {
  if (windows_.type() != CV_32FC1)
    throw std::invalid_argument("NearestWindows::WindowMatrix: float windows, one per row");
}

float NearestWindows::WindowMatrix::SquaredDistance(const float* query, int window,
                                                    float /*bound*/) const {
  const float* w = windows_.ptr<float>(window);
  float d = 0.0f;
  for (int i = 0; i < windows_.cols; ++i) d += (w[i] - query[i]) * (w[i] - query[i]);
  return d;
}

NearestWindows::NearestWindows(const Windows& windows, Options options)
    : options_(options), windows_(windows), tree_(std::make_unique<Tree>()) {
  if (windows_.Count() < 2 || windows_.Length() < kComponents || options_.candidates < 1 ||
      !(options_.eps >= 0.0f))
    throw std::invalid_argument(
        "NearestWindows: at least 2 windows of at least 8 values, candidates >= 1, eps >= 0");
  PrincipalComponents(windows_, kComponents, mean_, components_);
  tree_->projected = Project(windows_);
  tree_->points = tree_->projected.ptr<float>();
  tree_->index = std::make_unique<Tree::Index>(  // builds the tree
      components_.rows, *tree_, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
  tree_->StoreInTreeOrder();
}

NearestWindows::~NearestWindows() = default;

cv::Mat NearestWindows::Project(const Windows& rows) const {
  // A block of rows at a time (never every window at once), each less the mean,
  // then its components.
  cv::Mat out(rows.Count(), components_.rows, CV_32FC1);
  cv::Mat centred;
  const float* mean = mean_.ptr<float>();
  for (int first = 0; first < rows.Count(); first += kProjectedBlockRows) {
    const int count = std::min(kProjectedBlockRows, rows.Count() - first);
    centred.create(count, rows.Length(), CV_32FC1);
    rows.Rows(first, centred);
    for (int r = 0; r < count; ++r) {
      float* c = centred.ptr<float>(r);
      for (int i = 0; i < centred.cols; ++i) c[i] -= mean[i];
    }
    cv::Mat block = out.rowRange(first, first + count);
    cv::gemm(centred, components_, 1.0, cv::noArray(), 0.0, block, cv::GEMM_2_T);
  }
  return out;
}

void NearestWindows::Nearest(const cv::Mat& queries, std::vector<int>& index,
                             std::vector<float>& squared_distance) const {
  CV_Assert(queries.type() == CV_32FC1 && queries.cols == windows_.Length());
  const cv::Mat projected = Project(WindowMatrix(queries));
  const std::size_t k = static_cast<std::size_t>(std::min(options_.candidates, windows_.Count()));
  std::vector<std::uint32_t> found(k);
  std::vector<float> reduced_distance(k);
  index.assign(static_cast<std::size_t>(queries.rows), 0);
  squared_distance.assign(static_cast<std::size_t>(queries.rows),
                          std::numeric_limits<float>::max());
  for (int q = 0; q < queries.rows; ++q) {
    nanoflann::KNNResultSet<float, std::uint32_t> nearest(k);
    nearest.init(found.data(), reduced_distance.data());
    tree_->index->findNeighbors(nearest, projected.ptr<float>(q), SearchEps(options_.eps));
    const float* query = queries.ptr<float>(q);
    const std::size_t n = static_cast<std::size_t>(q);
    for (std::size_t c = 0; c < nearest.size(); ++c) {
      const int w = static_cast<int>(tree_->window_of_point[found[c]]);
      const float d = windows_.SquaredDistance(query, w, squared_distance[n]);
      if (d < squared_distance[n]) squared_distance[n] = d, index[n] = w;
    }
  }
}

}  // namespace texlume::synth
