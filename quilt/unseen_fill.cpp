#include "quilt/unseen_fill.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>

#include "ptm/coefficient_space.h"
#include "quilt/quilt_atlases.h"
#include "synth/planar_synthesis.h"

namespace texlume::quilt {
namespace {

// The quilt of the unseen faces over the job's layout, kept alive by the
// synthesis's fill: where a point of a filled face reads the sample.
class UnseenQuilt {
 public:
  UnseenQuilt(atlas::AtlasLayout layout, DenseSurface surface, QuiltResult quilt, int reach)
      : layout_(std::move(layout)), surface_(std::move(surface)), quilt_(std::move(quilt)) {
    lookup_.emplace(surface_, quilt_, layout_, reach);
  }
  UnseenQuilt(const UnseenQuilt&) = delete;  // the lookup refers to the members
  UnseenQuilt& operator=(const UnseenQuilt&) = delete;

  // The sample position at a point of a face's frame, and the turn from the
  // face frame into the sample's (d_sample = R(angle) d_face): the sample lies
  // turned by the lookup's angle a in the atlas frame, which is the face frame
  // turned by the atlas frame angle, so the turn is -a - that angle.
  bool At(int face, const Eigen::Vector2d& p_in_frame, Eigen::Vector2d* sample_px,
          double* face_to_sample_rad) const {
    double a = 0;
    if (!lookup_->At(face, p_in_frame, sample_px, &a)) return false;
    *face_to_sample_rad = -a - layout_.faces[static_cast<std::size_t>(face)].AtlasFrameAngle();
    return true;
  }

 private:
  atlas::AtlasLayout layout_;
  DenseSurface surface_;
  QuiltResult quilt_;
  std::optional<QuiltedSurfaceLookup> lookup_;  ///< over the members above
};

// What a face the photos placed shows at a point of its frame: the sample's
// features there, in the face frame; false where it shows none.
using FaceFeatures = std::function<bool(int face, const Eigen::Vector2d& p_in_frame, float* out)>;

GivenSamples GivenFromPhotoFaces(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                                 const synth::TriangleSynthesis& synthesis,
                                 const synth::MaterialSample& sample,
                                 const FaceFeatures& features_of) {
  const std::size_t nf = static_cast<std::size_t>(sample.NumFeatures());
  GivenSamples given;
  given.given.assign(surface.size(), false);
  given.features.assign(surface.size() * nf, 0.0f);
  for (std::size_t s = 0; s < surface.size(); ++s) {
    const DenseSample& d = surface.samples()[s];
    float* f = given.features.data() + s * nf;
    if (synthesis.patches[static_cast<std::size_t>(d.face)].source != synth::PatchSource::kPhotos ||
        !features_of(d.face, d.p_in_frame, f))
      continue;
    // The atlas frame is the face frame turned by the atlas frame angle (the
    // atlas bakers turn the values so).
    const double a = layout.faces[static_cast<std::size_t>(d.face)].AtlasFrameAngle();
    synth::Unfolding face_to_atlas;
    face_to_atlas.rotation = Eigen::Rotation2Dd(a).toRotationMatrix();
    face_to_atlas.coefficients_to_this = ptm::OrthonormalFrameRotation(a);
    sample.TurnFeatures(face_to_atlas, f);
    given.given[s] = true;
  }
  return given;
}

// The faces no photo placed, quilted from the others (their features given by
// `features_of`) over the layout of `options.atlas`; null when there are none.
std::shared_ptr<const UnseenQuilt> QuiltUnseenFaces(const mesh::TriangleMesh& mesh,
                                                    const synth::TriangleSynthesis& synthesis,
                                                    const synth::MaterialSample& sample,
                                                    const FaceFeatures& features_of,
                                                    const UnseenFillOptions& options,
                                                    const ProgressCallback& progress,
                                                    UnseenFillSummary& summary) {
  const auto start = std::chrono::steady_clock::now();
  summary.filled.assign(synthesis.patches.size(), false);
  for (std::size_t f = 0; f < synthesis.patches.size(); ++f)
    if (synthesis.patches[f].source != synth::PatchSource::kPhotos)
      summary.filled[f] = true, ++summary.faces;
  if (summary.faces == 0) return nullptr;
  atlas::AtlasLayout layout = atlas::LayoutAtlases(mesh, synthesis.patches, synthesis.unfoldings,
                                                   synthesis.texel_size, options.atlas, progress);
  DenseSurface surface = DenseSurface::Build(mesh, layout, synthesis.patches, synthesis.unfoldings,
                                             synthesis.texel_size);
  const GivenSamples given = GivenFromPhotoFaces(surface, layout, synthesis, sample, features_of);
  QuiltResult quilt = QuiltSurface(surface, layout, sample, options.quilt, progress, &given);
  summary.stats = quilt.stats;
  summary.given_samples = quilt.stats.given;
  summary.samples = surface.size() - quilt.stats.given;
  // A face's blend strip or seam band reads its neighbours W_e / 2 texels past
  // their edges: the lookup reaches that far, and over the gutter.
  const int reach = std::max(options.atlas.gutter, options.atlas.blend_strip);
  auto unseen = std::make_shared<const UnseenQuilt>(std::move(layout), std::move(surface),
                                                    std::move(quilt), reach);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return unseen;
}

// The features of a PTM synthesis's patch (MeshSynthesis::SamplePatch: its
// orthonormal coefficients, corrections and detail transfer included).
FaceFeatures PtmPatchFeatures(const synth::MeshSynthesis& synthesis) {
  return [&synthesis](int face, const Eigen::Vector2d& p, float* out) {
    std::array<float, synth::MeshSynthesis::kMaxPlanes> values{};
    if (!synthesis.SamplePatch(face, p, values.data())) return false;
    std::copy_n(values.begin(), synthesis.CoefficientPlanes(), out);
    return true;
  };
}

// The synthesis's own sample as a PTM, whose features (as a PtmSample) are
// its orthonormal coefficients.
ptm::Ptm SamplePtmOf(const synth::MeshSynthesis& synthesis) {
  return synth::FromOrthonormalPlanes(synthesis.sample_planes, synthesis.format);
}

}  // namespace

GivenSamples SamplesOfPhotoFaces(const DenseSurface& surface, const atlas::AtlasLayout& layout,
                                 const synth::MeshSynthesis& synthesis) {
  const ptm::Ptm sample_ptm = SamplePtmOf(synthesis);
  return GivenFromPhotoFaces(surface, layout, synthesis, synth::PtmSample(sample_ptm),
                             PtmPatchFeatures(synthesis));
}

UnseenFillSummary FillUnseenFaces(const mesh::TriangleMesh& mesh, synth::MeshSynthesis& synthesis,
                                  const UnseenFillOptions& options,
                                  const ProgressCallback& progress) {
  UnseenFillSummary summary;
  const ptm::Ptm sample_ptm = SamplePtmOf(synthesis);
  const synth::PtmSample sample(sample_ptm);
  const auto unseen = QuiltUnseenFaces(mesh, synthesis, sample, PtmPatchFeatures(synthesis),
                                       options, progress, summary);
  if (!unseen) return summary;
  // The sample's values at the lookup, turned from the sample's frame into the
  // face's (the coefficients of a frame turned by the angle).
  const std::vector<cv::Mat> planes = synthesis.sample_planes;
  const int polynomials = synthesis.CoefficientPlanes() / 6;
  synthesis.filled = summary.filled;
  synthesis.fill = [unseen, planes, polynomials](int face, const Eigen::Vector2d& p, float* out) {
    Eigen::Vector2d at;
    double face_to_sample = 0;
    if (!unseen->At(face, p, &at, &face_to_sample)) return false;
    SampleValuesTurned(planes, polynomials, at, face_to_sample, out);
    return true;
  };
  return summary;
}

UnseenFillSummary FillUnseenFaces(const mesh::TriangleMesh& mesh,
                                  synth::BtfMeshSynthesis& synthesis,
                                  const synth::BtfSample& sample, const UnseenFillOptions& options,
                                  const ProgressCallback& progress) {
  UnseenFillSummary summary;
  // What a placed face shows: the geometry maps where its lookup (seams
  // included) reads the sample; they do not turn with the frame. Where its
  // seam band takes a face the fill replaces, what it will show is the fill's:
  // not given.
  const FaceFeatures features_of = [&](int face, const Eigen::Vector2d& p, float* out) {
    const synth::BtfSampleLookup look = synthesis.Lookup(face, p);
    if (synthesis.patches[static_cast<std::size_t>(look.source_face)].source !=
        synth::PatchSource::kPhotos)
      return false;
    sample.FeaturesAt(look.sample_px, out);
    return true;
  };
  const auto unseen =
      QuiltUnseenFaces(mesh, synthesis, sample, features_of, options, progress, summary);
  if (!unseen) return summary;
  synthesis.filled = summary.filled;
  synthesis.fill = [unseen](int face, const Eigen::Vector2d& p, Eigen::Vector2d* sample_px,
                            double* face_to_sample_rad) {
    return unseen->At(face, p, sample_px, face_to_sample_rad);
  };
  return summary;
}

}  // namespace texlume::quilt
