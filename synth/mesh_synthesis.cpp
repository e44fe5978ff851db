#include "synth/mesh_synthesis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "core/errors.h"
#include "synth/coefficient_correction.h"
#include "synth/face_regions.h"

namespace texlume::synth {

void MeshSynthesisOptions::Check() const {
  TriangleEngineOptions::Check();
  if (!(correction_sigma > 0.0)) throw OptionError("correction_sigma must be > 0");
  if (!(correction_prior_shrink <= 1.0))
    throw OptionError("correction_prior_shrink must be in [0, 1], or < 0 to estimate it");
  if (!(correction_noise > 0.0) || !std::isfinite(correction_noise))
    throw OptionError("correction_noise must be > 0");
  if (correction_iterations < 0 || correction_iterations > 5)
    throw OptionError("correction_iterations must be in [0, 5]");
  if (std::isnan(detail_reach_texels))
    throw OptionError("detail_reach_texels must be a number (< 0: every cell)");
}

bool MeshSynthesis::SamplePatch(int face, const Eigen::Vector2d& p, float* out) const {
  if (!filled.empty() && filled[static_cast<std::size_t>(face)] && fill(face, p, out)) return true;
  return SamplePtmPatch(sample_planes, format, detail_bands,
                        patches[static_cast<std::size_t>(face)], texel_size, p, out);
}

void MeshSynthesis::SampleBlended(int face, const Eigen::Vector2d& p, int strip, float* out) const {
  const std::size_t n = sample_planes.size();  // <= kMaxPlanes
  std::array<float, kMaxPlanes> own{}, other{};
  if (!SamplePatch(face, p, own.data())) own.fill(0.0f);
  std::array<double, kMaxPlanes> sum{};
  double own_weight = 1.0;
  const TrianglePatch& patch = patches[static_cast<std::size_t>(face)];
  const double half_width = 0.5 * strip * texel_size;
  const int coefficient_planes = CoefficientPlanes();
  for (int k = 0; k < 3; ++k) {
    const Unfolding& u = unfoldings[static_cast<std::size_t>(face)][static_cast<std::size_t>(k)];
    if (u.face < 0) continue;
    const Eigen::Vector2d& a = patch.corners_in_frame[static_cast<std::size_t>(k)];
    const Eigen::Vector2d& b = patch.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)];
    const double d = mesh::DistanceToSegment(a, b, p);
    if (d >= half_width) continue;
    if (!SamplePatch(u.face, u.rotation * p + u.translation, other.data())) continue;
    const double w = 0.5 * (1.0 - d / half_width);  // 1/2 at the edge, 0 at W_e / 2
    for (int q = 0; q < coefficient_planes / 6; ++q) {
      Eigen::Matrix<double, 6, 1> c;
      for (int i = 0; i < 6; ++i) c[i] = other[static_cast<std::size_t>(q * 6 + i)];
      c = u.coefficients_to_this * c;
      for (int i = 0; i < 6; ++i) sum[static_cast<std::size_t>(q * 6 + i)] += w * c[i];
    }
    for (std::size_t c = static_cast<std::size_t>(coefficient_planes); c < n; ++c)
      sum[c] += w * other[c];
    own_weight -= w;
  }
  for (std::size_t c = 0; c < n; ++c) out[c] = static_cast<float>(own_weight * own[c] + sum[c]);
}

namespace {

// Summed squared coefficient difference across edge k of face f, and the points.
std::pair<double, int> EdgeDifference(const MeshSynthesis& synthesis, std::size_t f, int k) {
  const Unfolding& u = synthesis.unfoldings[f][static_cast<std::size_t>(k)];
  const TrianglePatch& patch = synthesis.patches[f];
  const Eigen::Vector2d a = patch.corners_in_frame[static_cast<std::size_t>(k)];
  const Eigen::Vector2d b = patch.corners_in_frame[static_cast<std::size_t>((k + 1) % 3)];
  const int points = std::max(1, static_cast<int>((b - a).norm() / synthesis.texel_size));
  const int planes = synthesis.CoefficientPlanes();
  std::array<float, MeshSynthesis::kMaxPlanes> own{}, other{};
  double sum = 0.0;
  int counted = 0;
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector2d p = a + (b - a) * ((i + 0.5) / points);
    if (!synthesis.SamplePatch(static_cast<int>(f), p, own.data()) ||
        !synthesis.SamplePatch(u.face, u.rotation * p + u.translation, other.data()))
      continue;
    for (int q = 0; q < planes / 6; ++q) {
      Eigen::Matrix<double, 6, 1> c, o;
      for (int j = 0; j < 6; ++j)
        c[j] = other[static_cast<std::size_t>(q * 6 + j)],
        o[j] = own[static_cast<std::size_t>(q * 6 + j)];
      sum += (u.coefficients_to_this * c - o).squaredNorm();
    }
    ++counted;
  }
  return {sum, counted};
}

}  // namespace

void EdgeTally::Add(double sum, int points) {
  ++edges_;
  if (points <= 0) return;
  sum_ += sum;
  points_ += static_cast<std::size_t>(points);
  const double edge_mean = sum / points, before = edge_mean - edge_mean_;
  edge_mean_ += before / static_cast<double>(++measured_edges_);
  edge_squares_ += before * (edge_mean - edge_mean_);
}

double EdgeTally::Mean() const { return points_ ? sum_ / static_cast<double>(points_) : 0.0; }

double EdgeTally::StandardError() const {
  const double n = static_cast<double>(measured_edges_);
  return measured_edges_ < 2 ? 0.0 : std::sqrt(edge_squares_ / (n - 1.0) / n);
}

EdgeMismatch MeasureEdgeMismatch(const MeshSynthesis& synthesis,
                                 const std::vector<int>& region_of_face) {
  const std::size_t num_faces = synthesis.patches.size();
  if (num_faces == 0) return {};
  // The regions' borders and the band rank 0 places first, from the unfoldings'
  // edge neighbours, as the distributed run computes them.
  std::vector<std::array<int, 3>> neighbours(num_faces);
  for (std::size_t f = 0; f < num_faces; ++f)
    for (std::size_t k = 0; k < 3; ++k) neighbours[f][k] = synthesis.unfoldings[f][k].face;
  mesh::FacePartition partition;
  partition.region_of_face =
      region_of_face.empty() ? std::vector<int>(num_faces, 0) : region_of_face;
  partition.num_regions =
      1 + *std::max_element(partition.region_of_face.begin(), partition.region_of_face.end());
  mesh::CountRegionBorders(neighbours, partition);
  const std::vector<char>& on_border = partition.on_border;
  const std::vector<char> in_band = BordersPlacedFirst(partition, neighbours);
  const auto region = [&](std::size_t f) { return partition.region_of_face[f]; };
  EdgeMismatch m;
  const double planes = std::max(1, synthesis.CoefficientPlanes());
  for (std::size_t f = 0; f < num_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = synthesis.unfoldings[f][static_cast<std::size_t>(k)].face;
      if (g < static_cast<int>(f)) continue;  // each shared edge once (and not boundaries)
      const auto [sum, points] = EdgeDifference(synthesis, f, k);
      const std::size_t other = static_cast<std::size_t>(g);
      if (region(f) != region(other)) {
        m.region_borders.Add(sum / planes, points);
        continue;
      }
      m.elsewhere.Add(sum / planes, points);
      if (on_border[f] != on_border[other]) m.next_to_borders.Add(sum / planes, points);
      if (in_band[f] != in_band[other]) m.next_to_band.Add(sum / planes, points);
    }
  return m;
}

MeshSynthesis SynthesizeMeshPtm(const mesh::TriangleMesh& mesh,
                                const sfm::Reconstruction& reconstruction,
                                const sfm::VisibilityResult& visibility,
                                const std::vector<MeshPhoto>& photos, const ptm::Ptm& ptm,
                                const MeshSynthesisOptions& options,
                                const ProgressCallback& progress, const FaceRegions* regions,
                                const ptm::SelfShadowing* sample_shadowing) {
  options.Check();
  const PtmSample sample(ptm, sample_shadowing);
  // The photo-consistency pass and detail transfer work on LRGB luminance.
  std::unique_ptr<CoefficientCorrection> correction;
  if (options.correction_iterations > 0 && ptm.format == ptm::PtmFormat::kLrgb)
    correction = std::make_unique<CoefficientCorrection>(sample, options);
  TriangleEngine engine(mesh, reconstruction, visibility, photos, sample, options,
                        correction.get());
  MeshSynthesis result;
  if (regions) engine.DistributeOver(*regions);
  static_cast<TriangleSynthesis&>(result) = engine.Run(progress);
  if (result.rank_share_only) return result;  // rank 0 finishes
  result.format = ptm.format;
  result.sample_planes = sample.Values();
  if (correction) result.detail_bands = correction->TakeDetailBands();
  return result;
}

}  // namespace texlume::synth
