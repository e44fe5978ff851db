#include "synth/mesh_btf.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "synth/channel_factor_correction.h"
#include "synth/graph_cut_seams.h"

namespace texlume::synth {
namespace {

double AngleOf(const Eigen::Matrix2d& r) { return std::atan2(r(1, 0), r(0, 0)); }

}  // namespace

void BtfMeshSynthesisOptions::Check() const {
  TriangleEngineOptions::Check();
  if (seam_band < 1 || seam_band > strip)
    throw OptionError("seam band must be in [1, strip] texels");
  if (!(correction_noise > 0.0) || !std::isfinite(correction_noise))
    throw OptionError("correction noise must be > 0");
  if (!(correction_sigma > 0.0) || !std::isfinite(correction_sigma))
    throw OptionError("correction sigma must be > 0 photo pixels");
}

BtfSampleLookup BtfMeshSynthesis::Lookup(int face, const Eigen::Vector2d& p) const {
  auto own = [&](int f, const Eigen::Vector2d& q, double angle) {
    const TrianglePatch& patch = patches[static_cast<std::size_t>(f)];
    BtfSampleLookup out;
    out.source_face = f;
    // d_sample = R(fill) d_f and d_f = R(angle) d_asked.
    if (!filled.empty() && filled[static_cast<std::size_t>(f)] &&
        fill(f, q, &out.sample_px, &out.angle_rad)) {
      out.angle_rad += angle;
      return out;
    }
    const Eigen::Vector2d in_patch((q.x() - patch.x_min) / texel_size,
                                   (patch.y_max - q.y()) / texel_size);  // texels, y down
    out.sample_px = Eigen::Vector2d(patch.sample_x, patch.sample_y) + in_patch;
    out.angle_rad = angle;
    if (static_cast<std::size_t>(f) < colour_gain.size() &&
        !colour_gain[static_cast<std::size_t>(f)].empty()) {
      // Bilinear on the factor grid (cell centres at (c + 0.5) / density texels).
      const cv::Mat& k = colour_gain[static_cast<std::size_t>(f)];
      const Eigen::Vector2d& density = gain_density[static_cast<std::size_t>(f)];
      const double u = std::clamp(in_patch.x() * density.x() - 0.5, 0.0, k.cols - 1.0);
      const double v = std::clamp(in_patch.y() * density.y() - 0.5, 0.0, k.rows - 1.0);
      const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
      const int x1 = std::min(x0 + 1, k.cols - 1), y1 = std::min(y0 + 1, k.rows - 1);
      const float fx = static_cast<float>(u - x0), fy = static_cast<float>(v - y0);
      const auto at = [&](int x, int y) {
        const cv::Vec3f& c = k.at<cv::Vec3f>(y, x);
        return Eigen::Vector3f(c[0], c[1], c[2]);
      };
      out.colour_gain = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) +
                        fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
    }
    return out;
  };
  const TrianglePatch& patch = patches[static_cast<std::size_t>(face)];
  const cv::Mat& label = labels[static_cast<std::size_t>(face)];
  const int i = static_cast<int>(std::floor((p.x() - patch.x_min) / texel_size));
  const int j = static_cast<int>(std::floor((patch.y_max - p.y()) / texel_size));
  const bool is_filled = !filled.empty() && filled[static_cast<std::size_t>(face)];
  if (is_filled || label.empty() || i < 0 || j < 0 || i >= label.cols || j >= label.rows)
    return own(face, p, 0);
  const int l = label.at<std::uint8_t>(j, i);
  if (l == 0) return own(face, p, 0);
  const Unfolding& u = unfoldings[static_cast<std::size_t>(face)][static_cast<std::size_t>(l - 1)];
  if (u.face < 0) return own(face, p, 0);
  return own(u.face, u.rotation * p + u.translation, AngleOf(u.rotation));
}

BtfMeshSynthesis SynthesizeMeshBtf(const mesh::TriangleMesh& mesh,
                                   const sfm::Reconstruction& reconstruction,
                                   const sfm::VisibilityResult& visibility,
                                   const std::vector<MeshPhoto>& photos,
                                   const btf::BtfFactorisation& btf,
                                   const BtfMeshSynthesisOptions& options,
                                   const ProgressCallback& progress, const FaceRegions* regions) {
  options.Check();
  const BtfSample sample(btf);
  ChannelFactorCorrection correction({options.correction_noise, options.correction_sigma,
                                      (options.seam_band + 1) * options.sample_texel_size});
  TriangleEngine engine(mesh, reconstruction, visibility, photos, sample, options,
                        options.photo_correction ? &correction : nullptr);
  BtfMeshSynthesis result;
  if (regions) engine.DistributeOver(*regions);
  static_cast<TriangleSynthesis&>(result) = engine.Run(progress);
  if (result.rank_share_only) return result;  // rank 0 finishes
  result.sample_width = btf.width;
  result.sample_height = btf.height;
  result.colour_gain = correction.factors();
  result.gain_density = correction.density();
  result.colour_gain.resize(result.patches.size());
  result.gain_density.resize(result.patches.size(), Eigen::Vector2d::Ones());
  result.photo_rms_quilted = correction.RmsQuilted();
  result.photo_rms_corrected = correction.RmsCorrected();
  SeamCut seams = CutSeams(result.patches, result.unfoldings, result.texel_size, sample,
                           options.seam_band, progress);
  result.labels = std::move(seams.labels);
  result.seam_edges = seams.seam_edges;
  result.seam_links = seams.seam_links;
  result.seam_cost = seams.seam_cost;
  result.edge_cost = seams.edge_cost;
  result.seam_cost_per_link = seams.seam_cost_per_link;
  result.edge_cost_per_link = seams.edge_cost_per_link;
  result.seconds_seams = seams.seconds;
  return result;
}

}  // namespace texlume::synth
