#include "synth/nearest_windows.h"

#include <algorithm>
#include <cstdint>
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
void PrincipalComponents(const cv::Mat& windows, int count, cv::Mat& mean, cv::Mat& directions) {
  const int step = std::max(1, (windows.rows + kMaxComponentRows - 1) / kMaxComponentRows);
  cv::Mat rows((windows.rows + step - 1) / step, windows.cols, CV_32FC1);
  for (int r = 0; r < windows.rows; r += step) windows.row(r).copyTo(rows.row(r / step));
  cv::Mat covariance, mean64, variances, all;
  cv::calcCovarMatrix(rows, covariance, mean64, cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_SCALE,
                      CV_64F);
  cv::eigen(covariance, variances, all);  // descending, symmetric
  mean64.convertTo(mean, CV_32F);
  all.rowRange(0, std::clamp(count, 1, all.rows)).convertTo(directions, CV_32F);
}

}  // namespace

// nanoflann's dataset adaptor over the projected windows (a row each).
struct NearestWindows::Tree {
  cv::Mat projected;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(projected.rows); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const {
    return projected.ptr<float>(static_cast<int>(i))[d];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Tree>, Tree,
                                                    -1, std::uint32_t>;
  std::unique_ptr<Index> index;
};

NearestWindows::NearestWindows(cv::Mat windows, Options options)
    : options_(options), windows_(std::move(windows)), tree_(std::make_unique<Tree>()) {
  if (windows_.type() != CV_32FC1 || windows_.rows < 2 || options_.components < 1 ||
      options_.candidates < 1 || !(options_.eps >= 0.0f))
    throw std::invalid_argument(
        "NearestWindows: float windows (at least 2), components and candidates >= 1, eps >= 0");
  PrincipalComponents(windows_, options_.components, mean_, components_);
  tree_->projected = Project(windows_);
  tree_->index = std::make_unique<Tree::Index>(  // builds the tree
      components_.rows, *tree_, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize));
}

NearestWindows::~NearestWindows() = default;

cv::Mat NearestWindows::Project(const cv::Mat& rows) const {
  // Each row less the mean, a block of rows at a time (no copy of every window at
  // once), then its components.
  cv::Mat out(rows.rows, components_.rows, CV_32FC1);
  cv::Mat centred;
  const float* mean = mean_.ptr<float>();
  for (int first = 0; first < rows.rows; first += kProjectedBlockRows) {
    const int count = std::min(kProjectedBlockRows, rows.rows - first);
    centred.create(count, rows.cols, CV_32FC1);
    for (int r = 0; r < count; ++r) {
      const float* in = rows.ptr<float>(first + r);
      float* c = centred.ptr<float>(r);
      for (int i = 0; i < rows.cols; ++i) c[i] = in[i] - mean[i];
    }
    cv::Mat block = out.rowRange(first, first + count);
    cv::gemm(centred, components_, 1.0, cv::noArray(), 0.0, block, cv::GEMM_2_T);
  }
  return out;
}

void NearestWindows::Nearest(const cv::Mat& queries, std::vector<int>& index,
                             std::vector<float>& squared_distance) const {
  CV_Assert(queries.type() == CV_32FC1 && queries.cols == windows_.cols);
  const cv::Mat projected = Project(queries);
  const std::size_t k = static_cast<std::size_t>(std::min(options_.candidates, windows_.rows));
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
      const float* window = windows_.ptr<float>(static_cast<int>(found[c]));
      float d = 0.0f;
      for (int i = 0; i < windows_.cols; ++i) d += (window[i] - query[i]) * (window[i] - query[i]);
      if (d < squared_distance[n]) squared_distance[n] = d, index[n] = static_cast<int>(found[c]);
    }
  }
}

}  // namespace texlume::synth
