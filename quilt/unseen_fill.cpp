#include "quilt/unseen_fill.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <memory>
#include <optional>

#include "ptm/coefficient_space.h"
#include "quilt/quilt_atlases.h"
#include "synth/planar_synthesis.h"

namespace texlume::quilt {
namespace {

// The quilt of the unseen faces, kept alive by MeshSynthesis::fill: what a
// point of a filled face shows, read from the sample at its quilted lookup.
class QuiltedFill {
 public:
  QuiltedFill(atlas::AtlasLayout layout, DenseSurface surface, QuiltResult quilt,
              const synth::MeshSynthesis& synthesis, int reach)
      : layout_(std::move(layout)),
        surface_(std::move(surface)),
        quilt_(std::move(quilt)),
        planes_(synthesis.sample_planes),
        polynomials_(synthesis.CoefficientPlanes() / 6) {
    lookup_.emplace(surface_, quilt_, layout_, reach);
    for (const atlas::FacePlacement& fp : layout_.faces)
      atlas_to_face_.push_back(ptm::OrthonormalFrameRotation(-fp.AtlasFrameAngle()));
  }

  // All planes at a point of the face's frame, in that frame: the sample's
  // values at the lookup, turned by the lookup's angle into the atlas frame
  // (as BakeQuiltedAtlases) and from there into the face frame (the inverse of
  // atlas::BuildAtlases' turn).
  bool At(int face, const Eigen::Vector2d& p_in_frame, float* out) const {
    Eigen::Vector2d at;
    double angle_rad = 0;
    if (!lookup_->At(face, p_in_frame, &at, &angle_rad)) return false;
    for (std::size_t k = 0; k < planes_.size(); ++k)
      out[k] = static_cast<float>(synth::BilinearClamped(planes_[k], at.x() - 0.5, at.y() - 0.5));
    const Eigen::Matrix<double, 6, 6> to_face =
        atlas_to_face_[static_cast<std::size_t>(face)] * ptm::OrthonormalFrameRotation(-angle_rad);
    for (int poly = 0; poly < polynomials_; ++poly) {
      Eigen::Matrix<double, 6, 1> c;
      for (int i = 0; i < 6; ++i) c[i] = out[poly * 6 + i];
      c = to_face * c;
      for (int i = 0; i < 6; ++i) out[poly * 6 + i] = static_cast<float>(c[i]);
    }
    return true;
  }

 private:
  atlas::AtlasLayout layout_;
  DenseSurface surface_;
  QuiltResult quilt_;
  std::vector<cv::Mat> planes_;
  int polynomials_;
  std::optional<QuiltedSurfaceLookup> lookup_;  ///< over the members above
  std::vector<Eigen::Matrix<double, 6, 6>> atlas_to_face_;
};

}  // namespace

GivenSamples SamplesOfPhotoFaces(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                                 const synth::MeshSynthesis& synthesis) {
  const int nf = synthesis.CoefficientPlanes();
  GivenSamples given;
  given.given.assign(surface.size(), false);
  given.features.assign(surface.size() * static_cast<std::size_t>(nf), 0.0f);
  std::array<float, synth::MeshSynthesis::kMaxPlanes> values{};
  for (std::size_t s = 0; s < surface.size(); ++s) {
    const DenseSample& d = surface.samples()[s];
    if (synthesis.patches[static_cast<std::size_t>(d.face)].source != synth::PatchSource::kPhotos ||
        !synthesis.SamplePatch(d.face, d.p_in_frame, values.data()))
      continue;
    // The atlas frame is the face frame turned by the atlas frame angle
    // (atlas::BuildAtlases turns the coefficients so).
    const Eigen::Matrix<double, 6, 6> to_atlas = ptm::OrthonormalFrameRotation(
        layout.faces[static_cast<std::size_t>(d.face)].AtlasFrameAngle());
    float* f = given.features.data() + s * static_cast<std::size_t>(nf);
    for (int poly = 0; poly < nf / 6; ++poly) {
      Eigen::Matrix<double, 6, 1> c;
      for (int i = 0; i < 6; ++i) c[i] = values[static_cast<std::size_t>(poly * 6 + i)];
      c = to_atlas * c;
      for (int i = 0; i < 6; ++i) f[poly * 6 + i] = static_cast<float>(c[i]);
    }
    given.given[s] = true;
  }
  return given;
}

UnseenFillSummary FillUnseenFaces(const mesh::TriangleMesh& mesh, synth::MeshSynthesis& synthesis,
                                  const UnseenFillOptions& options,
                                  const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  UnseenFillSummary summary;
  std::vector<bool> filled(synthesis.patches.size(), false);
  for (std::size_t f = 0; f < synthesis.patches.size(); ++f)
    if (synthesis.patches[f].source != synth::PatchSource::kPhotos)
      filled[f] = true, ++summary.faces;
  if (summary.faces == 0) return summary;
  atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, synthesis.patches, synthesis.unfoldings,
                                                   synthesis.texel_size, options.atlas, progress);
  DenseSurface surface =
      DenseSurface::Build(layout, synthesis.patches, synthesis.unfoldings, synthesis.texel_size);
  const GivenSamples given = SamplesOfPhotoFaces(surface, layout, synthesis);
  // The synthesis's own sample, whose features are its orthonormal coefficients.
  const ptm::Ptm sample_ptm =
      synth::FromOrthonormalPlanes(synthesis.sample_planes, synthesis.format);
  const synth::PtmSample sample(sample_ptm);
  QuiltResult quilt = QuiltSurface(surface, layout, sample, options.quilt, progress, &given);
  summary.stats = quilt.stats;
  summary.given_samples = quilt.stats.given;
  summary.samples = surface.size() - quilt.stats.given;
  // A filled face's blend strip reads its neighbours' values W_e / 2 texels past
  // their edges: the lookup reaches that far, and over the gutter.
  const int reach = std::max(options.atlas.gutter, options.atlas.blend_strip);
  auto fill = std::make_shared<const QuiltedFill>(std::move(layout), std::move(surface),
                                                  std::move(quilt), synthesis, reach);
  summary.filled = filled;
  synthesis.filled = std::move(filled);
  synthesis.fill = [fill](int face, const Eigen::Vector2d& p_in_frame, float* out) {
    return fill->At(face, p_in_frame, out);
  };
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace texlume::quilt
