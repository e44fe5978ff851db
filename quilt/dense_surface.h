#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "atlas/atlas.h"
#include "mesh/mesh.h"
#include "mesh/triangle_frame.h"
#include "synth/triangle_parts.h"

// The dense surface of graph-cut quilting (paper 004 §III-A, "GIM-based
// sampling"): one sample per atlas texel whose centre lies inside a triangle,
// so that synthesising the samples is synthesising the atlas texels. Inside a
// chart a sample's neighbours are its 4 atlas neighbours; across a chart's
// border they are found on the mesh (the texel one step away, carried over the
// shared edges into the neighbouring face and its chart), which zips the charts
// together as the paper's multi-chart geometry image does.

namespace texlume::quilt {

struct DenseSample {
  int atlas = 0, x = 0, y = 0;  ///< the atlas texel (x right, y down)
  int face = 0, chart = 0;
  Eigen::Vector2d p_in_frame = Eigen::Vector2d::Zero();  ///< texel centre, face frame, world units
};

/// The memory quilting a mesh's dense surface at `texel_size` (world units)
/// with `features` features per sample takes, bytes: per sample its lookup,
/// patch, features, links and index (about 64 bytes plus 4 per feature) and
/// the remembered seams (Kwatra's old seams: two feature vectors and a hash
/// node, on at most about one link in two); the charts' stretch adds up to
/// 1.25^2 samples per unit of area. Per face, the surface keeps the mesh, the
/// face frames, neighbours and corners, and the job its patch geometry and
/// atlas placement.
double QuiltingBytes(const mesh::TriangleMesh& mesh, double texel_size, int features);

class DenseSurface {
 public:
  /// Samples every texel inside a face of `layout` (atlas::VisitAtlasTexels,
  /// the first face wins on a shared edge) and links them. `mesh`, `patches`
  /// and `unfoldings` are those the layout was made from (synth::PatchGeometry);
  /// the surface keeps the mesh and the faces' corners (ConformalMap).
  static DenseSurface Build(const mesh::TriangleMesh& mesh, const atlas::AtlasLayout& layout,
                            const std::vector<synth::TrianglePatch>& patches,
                            const std::vector<std::array<synth::Unfolding, 3>>& unfoldings,
                            double texel_size);

  const std::vector<DenseSample>& samples() const { return samples_; }
  std::size_t size() const { return samples_.size(); }
  /// The samples linked to sample s (undirected, each once, ascending).
  std::span<const int> Neighbours(int s) const;
  /// The sample at an atlas texel, or -1.
  int At(int atlas, int x, int y) const;
  /// The sample's position in the world (world units).
  Eigen::Vector3d PointInWorld(int s) const;
  /// A face's triangle frame (synth::TrianglePatch::frame).
  const mesh::TriangleFrame& FrameOf(int face) const {
    return frames_[static_cast<std::size_t>(face)];
  }
  double texel_size() const { return texel_size_; }
  /// The least-squares conformal map of faces joined by edges (atlas::
  /// LeastSquaresConformalMap): per face, the map from its frame (texels) into
  /// the chart (texels, y up); false when they are not joined by edges, or a
  /// face is flipped or scaled beyond 4 either way.
  bool ConformalMap(const std::vector<int>& faces,
                    std::vector<std::pair<Eigen::Matrix2d, Eigen::Vector2d>>* frame_to_chart) const;

  std::size_t links() const { return adjacency_.size() / 2; }
  std::size_t chart_seam_links() const { return chart_seam_links_; }
  /// Sample directions with no neighbour (the mesh's border, or a step that
  /// lands outside every sample).
  std::size_t open_directions() const { return open_directions_; }

 private:
  friend class DenseSurfaceBuilder;
  bool EdgeConnected(const std::vector<int>& faces) const;

  std::vector<mesh::TriangleFrame> frames_;  ///< per face
  mesh::TriangleMesh mesh_;
  std::vector<std::array<int, 3>> face_neighbours_;             ///< mesh::FaceNeighbours
  std::vector<std::array<Eigen::Vector2d, 3>> corners_texels_;  ///< per face, in its frame
  double texel_size_ = 0;
  std::vector<DenseSample> samples_;
  std::vector<cv::Mat> index_;  ///< per atlas, CV_32SC1: sample or -1
  std::vector<int> offsets_, adjacency_;
  std::size_t chart_seam_links_ = 0, open_directions_ = 0;
};

/// A face's atlas frame in the world: x right and y up as its chart lies in
/// the atlas, and the face normal.
struct AtlasAxes {
  Eigen::Vector3d x, y, normal;
};
AtlasAxes AtlasAxesOf(const DenseSurface& surface, const atlas::AtlasLayout& layout, int face);

}  // namespace texlume::quilt
