#include "quilt/dense_surface.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "atlas/chart_parts.h"
#include "atlas/charts.h"

namespace texlume::quilt {

// Builds a DenseSurface in three steps: the samples, the links inside charts,
// the links across charts.
class DenseSurfaceBuilder {
 public:
  DenseSurfaceBuilder(const atlas::AtlasLayout& layout,
                      const std::vector<synth::TrianglePatch>& patches,
                      const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                      double texel_size)
      : layout_(layout), patches_(patches), unfoldings_(unfoldings), texel_size_(texel_size) {}

  DenseSurface Build() {
    TakeSamples();
    LinkSamples();
    MakeAdjacency();
    return std::move(out_);
  }

 private:
  static constexpr int kMostHops = 4;  ///< faces a one-texel step may cross

  void TakeSamples() {
    for (const synth::TrianglePatch& patch : patches_) out_.frames_.push_back(patch.frame);
    out_.texel_size_ = texel_size_;
    for (const cv::Size& size : layout_.atlas_sizes) out_.index_.emplace_back(size, CV_32SC1, -1);
    atlas::VisitAtlasTexels(
        layout_, texel_size_, 0, [&](int atlas, int x, int y, int face, const Eigen::Vector2d& p) {
          if (!InsideFace(face, x, y)) return;  // the half-texel ring VisitAtlasTexels adds
          out_.index_[static_cast<std::size_t>(atlas)].at<int>(y, x) =
              static_cast<int>(out_.samples_.size());
          out_.samples_.push_back(
              {atlas, x, y, face, layout_.faces[static_cast<std::size_t>(face)].chart, p});
        });
  }

  // As VisitAtlasTexels decides it: the texel centre inside the face's atlas triangle.
  bool InsideFace(int face, int x, int y) const {
    return mesh::SignedDistanceToTriangle(layout_.faces[static_cast<std::size_t>(face)].corners_px,
                                          Eigen::Vector2d(x + 0.5, y + 0.5)) <= 0.0;
  }

  // Each sample's 4 atlas directions: the atlas neighbour when it is a sample
  // of the same chart, otherwise the point one texel away found on the mesh.
  void LinkSamples() {
    static constexpr std::array<std::array<int, 2>, 4> kSteps{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
    for (std::size_t s = 0; s < out_.samples_.size(); ++s) {
      const DenseSample& a = out_.samples_[s];
      for (const auto& [dx, dy] : kSteps) {
        int b = out_.At(a.atlas, a.x + dx, a.y + dy);
        if (b >= 0 && out_.samples_[static_cast<std::size_t>(b)].chart != a.chart) b = -1;
        if (b < 0) b = AcrossCharts(a, Eigen::Vector2d(dx, dy));
        if (b < 0 || b == static_cast<int>(s)) {
          ++out_.open_directions_;
          continue;
        }
        edges_.emplace_back(std::min(static_cast<int>(s), b), std::max(static_cast<int>(s), b));
      }
    }
  }

  // The sample at the texel centre one step (atlas pixels) from `a`, carried
  // across shared edges (synth::Unfolding) into the face that holds it.
  int AcrossCharts(const DenseSample& a, const Eigen::Vector2d& step_px) const {
    const atlas::FacePlacement& start = layout_.faces[static_cast<std::size_t>(a.face)];
    const Eigen::Vector2d target_px(a.x + 0.5 + step_px.x(), a.y + 0.5 + step_px.y());
    Eigen::Vector2d p = start.FrameFromAtlas(target_px, texel_size_);
    int face = a.face;
    for (int hop = 0; hop < kMostHops; ++hop) {
      const int edge = CrossedEdge(face, p);
      if (edge < 0) return SampleNear(face, p);
      const synth::Unfolding& u =
          unfoldings_[static_cast<std::size_t>(face)][static_cast<std::size_t>(edge)];
      if (u.face < 0) return -1;  // the mesh's border
      p = u.rotation * p + u.translation;
      face = u.face;
    }
    return -1;
  }

  // The edge (k: corners k, k+1) that p lies beyond, the one of its most
  // negative barycentric coordinate; -1 inside the triangle.
  int CrossedEdge(int face, const Eigen::Vector2d& p) const {
    const auto& c = patches_[static_cast<std::size_t>(face)].corners_in_frame;
    const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
      return u.x() * v.y() - u.y() * v.x();
    };
    const double area = cross(c[1] - c[0], c[2] - c[0]);
    int edge = -1;
    double most_negative = -1e-9;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d& from = c[static_cast<std::size_t>(k)];
      const Eigen::Vector2d& to = c[static_cast<std::size_t>((k + 1) % 3)];
      const double opposite_weight = cross(to - from, p - from) / area;  // of corner k + 2
      if (opposite_weight < most_negative) most_negative = opposite_weight, edge = k;
    }
    return edge;
  }

  // The sample of the face's chart whose texel centre is nearest to the point,
  // within a texel: texel centres just inside an edge are the samples there.
  int SampleNear(int face, const Eigen::Vector2d& p_in_frame) const {
    const atlas::FacePlacement& fp = layout_.faces[static_cast<std::size_t>(face)];
    const Eigen::Vector2d r = fp.linear * p_in_frame / texel_size_;
    const Eigen::Vector2d px(fp.offset.x() + r.x(), fp.offset.y() - r.y());
    const int x0 = static_cast<int>(std::floor(px.x())), y0 = static_cast<int>(std::floor(px.y()));
    int best = -1;
    double best_d2 = 1.0;
    for (int y = y0 - 1; y <= y0 + 1; ++y)
      for (int x = x0 - 1; x <= x0 + 1; ++x) {
        const int s = out_.At(fp.atlas, x, y);
        if (s < 0 || out_.samples_[static_cast<std::size_t>(s)].chart != fp.chart) continue;
        const double d2 = (Eigen::Vector2d(x + 0.5, y + 0.5) - px).squaredNorm();
        if (d2 <= best_d2) best_d2 = d2, best = s;
      }
    return best;
  }

  void MakeAdjacency() {
    std::sort(edges_.begin(), edges_.end());
    edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
    std::vector<int> degree(out_.samples_.size() + 1, 0);
    for (const auto& [a, b] : edges_) {
      ++degree[static_cast<std::size_t>(a) + 1], ++degree[static_cast<std::size_t>(b) + 1];
      if (out_.samples_[static_cast<std::size_t>(a)].chart !=
          out_.samples_[static_cast<std::size_t>(b)].chart)
        ++out_.chart_seam_links_;
    }
    for (std::size_t i = 1; i < degree.size(); ++i) degree[i] += degree[i - 1];
    out_.offsets_ = degree;
    out_.adjacency_.assign(static_cast<std::size_t>(degree.back()), -1);
    std::vector<int> fill(degree.begin(), degree.end() - 1);
    for (const auto& [a, b] : edges_) {
      out_.adjacency_[static_cast<std::size_t>(fill[static_cast<std::size_t>(a)]++)] = b;
      out_.adjacency_[static_cast<std::size_t>(fill[static_cast<std::size_t>(b)]++)] = a;
    }
    for (std::size_t s = 0; s < out_.samples_.size(); ++s)
      std::sort(out_.adjacency_.begin() + out_.offsets_[s],
                out_.adjacency_.begin() + out_.offsets_[s + 1]);
  }

  const atlas::AtlasLayout& layout_;
  const std::vector<synth::TrianglePatch>& patches_;
  const std::vector<std::array<synth::Unfolding, 3>>& unfoldings_;
  const double texel_size_;
  DenseSurface out_;
  std::vector<std::pair<int, int>> edges_;
};

DenseSurface DenseSurface::Build(const mesh::TriangleMesh& mesh, const atlas::AtlasLayout& layout,
                                 const std::vector<synth::TrianglePatch>& patches,
                                 const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                                 double texel_size) {
  DenseSurface surface = DenseSurfaceBuilder(layout, patches, unfoldings, texel_size).Build();
  surface.mesh_ = mesh;
  surface.face_neighbours_ = mesh::FaceNeighbours(mesh);
  for (const synth::TrianglePatch& patch : patches)
    surface.corners_texels_.push_back(atlas::chart_parts::FrameCornersTexels(patch, texel_size));
  return surface;
}

bool DenseSurface::EdgeConnected(const std::vector<int>& faces) const {
  std::unordered_map<int, bool> reached;  // face of the set -> reached from the first
  for (const int f : faces) reached[f] = false;
  std::vector<int> stack{faces[0]};
  reached[faces[0]] = true;
  std::size_t count = 1;
  while (!stack.empty()) {
    const int f = stack.back();
    stack.pop_back();
    for (const int n : face_neighbours_[static_cast<std::size_t>(f)]) {
      const auto it = reached.find(n);
      if (it != reached.end() && !it->second) it->second = true, ++count, stack.push_back(n);
    }
  }
  return count == reached.size();
}

bool DenseSurface::ConformalMap(
    const std::vector<int>& faces,
    std::vector<std::pair<Eigen::Matrix2d, Eigen::Vector2d>>* frame_to_chart) const {
  // Faces joined only at a vertex turn freely about it: no unique map.
  if (faces.empty() || !EdgeConnected(faces)) return false;
  std::vector<atlas::chart_parts::Corners> uv;
  if (!atlas::LeastSquaresConformalMap(
          mesh_, [&](int f) { return corners_texels_[static_cast<std::size_t>(f)]; }, faces,
          texel_size_, &uv))
    return false;
  frame_to_chart->clear();
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const atlas::ChartFace map = atlas::chart_parts::AffineBetween(
        faces[i], corners_texels_[static_cast<std::size_t>(faces[i])], uv[i]);
    // A flipped face, or one scaled beyond 4 either way: no usable map.
    if (!map.linear.allFinite() || !(map.linear.determinant() > 0)) return false;
    const Eigen::Vector2d scales = Eigen::JacobiSVD<Eigen::Matrix2d>(map.linear).singularValues();
    if (!(scales.maxCoeff() <= 4.0 && scales.minCoeff() >= 0.25)) return false;
    frame_to_chart->emplace_back(map.linear, map.translation);
  }
  return true;
}

std::span<const int> DenseSurface::Neighbours(int s) const {
  const auto i = static_cast<std::size_t>(s);
  return {adjacency_.data() + offsets_[i], adjacency_.data() + offsets_[i + 1]};
}

int DenseSurface::At(int atlas, int x, int y) const {
  if (atlas < 0 || atlas >= static_cast<int>(index_.size())) return -1;
  const cv::Mat& index = index_[static_cast<std::size_t>(atlas)];
  if (x < 0 || y < 0 || x >= index.cols || y >= index.rows) return -1;
  return index.at<int>(y, x);
}

Eigen::Vector3d DenseSurface::PointInWorld(int s) const {
  const DenseSample& d = samples_[static_cast<std::size_t>(s)];
  const mesh::TriangleFrame& f = frames_[static_cast<std::size_t>(d.face)];
  return f.origin_in_world + d.p_in_frame.x() * f.x_axis + d.p_in_frame.y() * f.y_axis;
}

double QuiltingBytes(const mesh::TriangleMesh& mesh, double texel_size, int features) {
  const std::vector<double> areas = mesh::FaceAreas(mesh);
  const double area = std::accumulate(areas.begin(), areas.end(), 0.0);
  const double samples = 1.6 * area / (texel_size * texel_size);
  // Per face: the surface's frame, mesh face, neighbours and corners, and a
  // vertex or more (an unshared mesh has three); the job's patch geometry (a
  // triangle patch and its three unfoldings) and atlas placement.
  const double per_face = sizeof(mesh::TriangleFrame) + 3 * sizeof(int) + 3 * sizeof(int) +
                          3 * sizeof(Eigen::Vector2d) + 3 * sizeof(Eigen::Vector3d) +
                          sizeof(synth::TrianglePatch) + 3 * sizeof(synth::Unfolding) +
                          sizeof(atlas::FacePlacement);
  return samples * (64 + 4.0 * features + 0.5 * (2 * 4.0 * features + 96)) +
         per_face * static_cast<double>(mesh.faces.size());
}

AtlasAxes AtlasAxesOf(const DenseSurface& surface, const atlas::AtlasLayout& layout, int face) {
  const mesh::TriangleFrame& frame = surface.FrameOf(face);
  const double a = layout.faces[static_cast<std::size_t>(face)].AtlasFrameAngle();
  const Eigen::Vector3d x = std::cos(a) * frame.x_axis + std::sin(a) * frame.y_axis;
  return {x, frame.z_axis.cross(x), frame.z_axis};
}

}  // namespace texlume::quilt
