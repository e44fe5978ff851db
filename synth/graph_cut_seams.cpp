#include "synth/graph_cut_seams.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>

#include "synth/min_cut.h"

namespace texlume::synth {
namespace {

int NearestEdge(const std::array<Eigen::Vector2d, 3>& c, const Eigen::Vector2d& p) {
  int best = 0;
  double best_d = std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < 3; ++k) {
    const double d = mesh::DistanceToSegment(c[k], c[(k + 1) % 3], p);
    if (d < best_d) best_d = d, best = static_cast<int>(k);
  }
  return best;
}

constexpr int kDi[4] = {1, -1, 0, 0}, kDj[4] = {0, 0, 1, -1};

// The cut across one shared edge: face f's edge k, which is edge kh of face h.
// Nodes are f's patch texels within the band whose nearest edge (of their own
// triangle) is this one, on f's side or the neighbour's.
class EdgeCut {
 public:
  EdgeCut(const std::vector<TrianglePatch>& patches, std::size_t f, int k, std::size_t h, int kh,
          const Unfolding& u, double texel_size, double band, const MaterialSample& sample)
      : patch_(patches[f]),
        other_(patches[h]),
        u_(u),
        k_(k),
        kh_(kh),
        t_(texel_size),
        band_(band),
        sample_(sample),
        a_(patch_.corners_in_frame[static_cast<std::size_t>(k)]),
        b_(patch_.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)]),
        node_(static_cast<std::size_t>(patch_.width * patch_.height), -1),
        side_(static_cast<std::size_t>(patch_.width * patch_.height), 0) {
    // Side of the edge a point is on: +1 towards f's third corner.
    own_sign_ =
        Cross(patch_.corners_in_frame[static_cast<std::size_t>((k + 2) % 3)]) >= 0 ? 1.0 : -1.0;
  }

  // Collects the nodes; false when the band holds none.
  bool CollectNodes() {
    const int w = patch_.width, hgt = patch_.height;
    for (int j = 0; j < hgt; ++j) {
      for (int i = 0; i < w; ++i) {
        const Eigen::Vector2d p = Centre(i, j);
        const bool on_f = Cross(p) * own_sign_ >= 0;
        side_[static_cast<std::size_t>(j * w + i)] = on_f ? 1 : -1;
        if (mesh::DistanceToSegment(a_, b_, p) > band_) continue;
        const Eigen::Vector2d q = u_.rotation * p + u_.translation;
        if (on_f ? NearestEdge(patch_.corners_in_frame, p) != k_
                 : NearestEdge(other_.corners_in_frame, q) != kh_)
          continue;
        const double sx = (q.x() - other_.x_min) / t_, sy = (other_.y_max - q.y()) / t_;
        if (sx < 0 || sy < 0 || sx > other_.width || sy > other_.height) continue;
        node_[static_cast<std::size_t>(j * w + i)] = static_cast<int>(cells_.size());
        cells_.emplace_back(i, j);
      }
    }
    return !cells_.empty();
  }

  // Builds and solves the graph: E_smooth's V(p, q) on the links, plus a
  // little per link so seams stay short; hard t-links next to the band's
  // outside, otherwise a vanishing preference for the texel's own side.
  // Adds the straight seam's cost (along the mesh edge) to edge_cost.
  void Solve(double& edge_cost, std::size_t& edge_links) {
    diff_.resize(cells_.size());
    for (std::size_t c = 0; c < cells_.size(); ++c)
      diff_[c] = Difference(Centre(cells_[c].first, cells_[c].second));
    const int w = patch_.width, hgt = patch_.height;
    MinCut cut(static_cast<int>(cells_.size()), static_cast<int>(2 * cells_.size()));
    constexpr double kHard = 1e9;
    for (std::size_t c = 0; c < cells_.size(); ++c) {
      const auto [i, j] = cells_[c];
      const int s = side_[static_cast<std::size_t>(j * w + i)];
      bool hard = false;
      for (int m = 0; m < 4; ++m) {
        const int ii = i + kDi[m], jj = j + kDj[m];
        const bool inside = ii >= 0 && jj >= 0 && ii < w && jj < hgt;
        const int other_node = inside ? node_[static_cast<std::size_t>(jj * w + ii)] : -1;
        if (other_node < 0) {
          // Next to a texel outside the band on this side: it keeps its own patch.
          if (!inside || side_[static_cast<std::size_t>(jj * w + ii)] == s) hard = true;
        } else if (m % 2 == 0) {  // each pair once (right and down)
          cut.Link(static_cast<int>(c), other_node,
                   diff_[c] + diff_[static_cast<std::size_t>(other_node)] + 1e-6);
        }
        if (other_node >= 0 && m % 2 == 0 && side_[static_cast<std::size_t>(jj * w + ii)] != s) {
          edge_cost += diff_[c] + diff_[static_cast<std::size_t>(other_node)];
          ++edge_links;
        }
      }
      const double keep = hard ? kHard : 1e-9;
      cut.Terminals(static_cast<int>(c), s > 0 ? 0.0 : keep, s > 0 ? keep : 0.0);
    }
    cut.Solve();
    is_a_.resize(cells_.size());
    for (std::size_t c = 0; c < cells_.size(); ++c) is_a_[c] = cut.IsA(static_cast<int>(c));
  }

  // Face f's labels where the cut chose the neighbour; the cut's cost.
  void LabelOwnFace(cv::Mat& labels, double& cut_cost, std::size_t& seam_links) const {
    const int w = patch_.width, hgt = patch_.height;
    for (std::size_t c = 0; c < cells_.size(); ++c) {
      const auto [i, j] = cells_[c];
      if (!is_a_[c]) labels.at<std::uint8_t>(j, i) = static_cast<std::uint8_t>(1 + k_);
      for (int m = 0; m < 4; m += 2) {
        const int ii = i + kDi[m], jj = j + kDj[m];
        if (ii >= w || jj >= hgt) continue;
        const int o = node_[static_cast<std::size_t>(jj * w + ii)];
        if (o >= 0 && is_a_[c] != is_a_[static_cast<std::size_t>(o)]) {
          cut_cost += diff_[c] + diff_[static_cast<std::size_t>(o)];
          ++seam_links;
        }
      }
    }
  }

  // The neighbour's texels near the edge take the cut's label at the nearest
  // cell of f's grid: where it chose A, they show f's patch.
  void LabelNeighbour(cv::Mat& nb_labels) const {
    const Eigen::Matrix2d back = u_.rotation.transpose();
    const int w = patch_.width, hgt = patch_.height;
    for (int j = 0; j < other_.height; ++j) {
      for (int i = 0; i < other_.width; ++i) {
        const Eigen::Vector2d q(other_.x_min + (i + 0.5) * t_, other_.y_max - (j + 0.5) * t_);
        const Eigen::Vector2d p = back * (q - u_.translation);
        if (mesh::DistanceToSegment(a_, b_, p) > band_ + t_) continue;
        const int ci = static_cast<int>(std::floor((p.x() - patch_.x_min) / t_));
        const int cj = static_cast<int>(std::floor((patch_.y_max - p.y()) / t_));
        if (ci < 0 || cj < 0 || ci >= w || cj >= hgt) continue;
        const int c = node_[static_cast<std::size_t>(cj * w + ci)];
        if (c >= 0 && is_a_[static_cast<std::size_t>(c)] &&
            side_[static_cast<std::size_t>(cj * w + ci)] < 0)
          nb_labels.at<std::uint8_t>(j, i) = static_cast<std::uint8_t>(1 + kh_);
      }
    }
  }

 private:
  double Cross(const Eigen::Vector2d& p) const {
    return (b_ - a_).x() * (p - a_).y() - (b_ - a_).y() * (p - a_).x();
  }
  Eigen::Vector2d Centre(int i, int j) const {
    return Eigen::Vector2d(patch_.x_min + (i + 0.5) * t_, patch_.y_max - (j + 0.5) * t_);
  }
  // |f_A(p) - f_B(p)|: the two patches' feature vectors at a point of f's frame.
  double Difference(const Eigen::Vector2d& p) const {
    const std::size_t n = static_cast<std::size_t>(sample_.NumFeatures());
    std::vector<float> fa(n), fb(n);
    sample_.FeaturesAt(Eigen::Vector2d(patch_.sample_x + (p.x() - patch_.x_min) / t_,
                                       patch_.sample_y + (patch_.y_max - p.y()) / t_),
                       fa.data());
    const Eigen::Vector2d q = u_.rotation * p + u_.translation;
    sample_.FeaturesAt(Eigen::Vector2d(other_.sample_x + (q.x() - other_.x_min) / t_,
                                       other_.sample_y + (other_.y_max - q.y()) / t_),
                       fb.data());
    double d = 0.0;
    for (std::size_t c = 0; c < n; ++c) d += (fa[c] - fb[c]) * (fa[c] - fb[c]);
    return std::sqrt(d);
  }

  const TrianglePatch& patch_;
  const TrianglePatch& other_;
  const Unfolding& u_;
  const int k_, kh_;
  const double t_, band_;
  const MaterialSample& sample_;
  const Eigen::Vector2d a_, b_;
  double own_sign_ = 1.0;
  std::vector<int> node_;
  std::vector<signed char> side_;  // +1 f, -1 the neighbour
  std::vector<std::pair<int, int>> cells_;
  std::vector<double> diff_;
  std::vector<char> is_a_;
};

}  // namespace

SeamCut CutSeams(const std::vector<TrianglePatch>& patches,
                 const std::vector<std::array<Unfolding, 3>>& unfoldings, double t,
                 const MaterialSample& sample, int seam_band, const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_faces = patches.size();
  SeamCut out;
  out.labels.resize(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f)
    out.labels[f] = cv::Mat::zeros(patches[f].height, patches[f].width, CV_8UC1);
  double edge_cost = 0.0;
  std::size_t edge_links = 0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const Unfolding& u = unfoldings[f][static_cast<std::size_t>(k)];
      if (u.face < 0 || static_cast<std::size_t>(u.face) < f) continue;  // each edge once
      const std::size_t h = static_cast<std::size_t>(u.face);
      int kh = -1;  // the shared edge's index in the neighbour
      for (int m = 0; m < 3; ++m)
        if (unfoldings[h][static_cast<std::size_t>(m)].face == static_cast<int>(f)) kh = m;
      if (kh < 0) continue;
      EdgeCut cut(patches, f, k, h, kh, u, t, seam_band * t, sample);
      if (!cut.CollectNodes()) continue;
      cut.Solve(edge_cost, edge_links);
      cut.LabelOwnFace(out.labels[f], out.seam_cost, out.seam_links);
      cut.LabelNeighbour(out.labels[h]);
      ++out.seam_edges;
    }
    if (progress && ((f + 1) % 256 == 0 || f + 1 == num_faces))
      progress("graph-cut seams", f + 1, num_faces);
  }
  out.edge_cost = edge_cost;
  out.seam_cost_per_link =
      out.seam_links ? out.seam_cost / static_cast<double>(out.seam_links) : 0.0;
  out.edge_cost_per_link = edge_links ? edge_cost / static_cast<double>(edge_links) : 0.0;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace texlume::synth
