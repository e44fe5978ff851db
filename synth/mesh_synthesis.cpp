#include "synth/mesh_synthesis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "core/errors.h"
#include "synth/coefficient_correction.h"

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

MeshSynthesis SynthesizeMeshPtm(const mesh::TriangleMesh& mesh,
                                const sfm::Reconstruction& reconstruction,
                                const sfm::VisibilityResult& visibility,
                                const std::vector<MeshPhoto>& photos, const ptm::Ptm& ptm,
                                const MeshSynthesisOptions& options,
                                const ProgressCallback& progress) {
  options.Check();
  const PtmSample sample(ptm);
  // The photo-consistency pass and detail transfer work on LRGB luminance.
  std::unique_ptr<CoefficientCorrection> correction;
  if (options.correction_iterations > 0 && ptm.format == ptm::PtmFormat::kLrgb)
    correction = std::make_unique<CoefficientCorrection>(sample, options);
  TriangleEngine engine(mesh, reconstruction, visibility, photos, sample, options,
                        correction.get());
  MeshSynthesis result;
  static_cast<TriangleSynthesis&>(result) = engine.Run(progress);
  result.format = ptm.format;
  result.sample_planes = sample.Values();
  if (correction) result.detail_bands = correction->TakeDetailBands();
  return result;
}

}  // namespace texlume::synth
