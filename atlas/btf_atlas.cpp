#include "atlas/btf_atlas.h"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "ptm/coefficient_space.h"

namespace texlume::atlas {
namespace {

double WrapAngle(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

// Preview lights: the zenith and rings of 6 at 60, 40, 25 and 15 degrees.
std::vector<Eigen::Vector3d> PreviewLights() {
  std::vector<Eigen::Vector3d> out = {Eigen::Vector3d::UnitZ()};
  const double elevations[] = {60, 40, 25, 15};
  for (int r = 0; r < 4; ++r) {
    const double e = elevations[r] * std::numbers::pi / 180.0;
    for (int k = 0; k < 6; ++k) {
      const double a = (k + 0.5 * (r % 2)) * std::numbers::pi / 3.0;
      out.emplace_back(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    }
  }
  return out;
}

}  // namespace

BtfAtlases BakeBtfAtlases(AtlasLayout layout, double texel_size, int gutter,
                          const btf::BtfFactorisation& sample, const BtfTexelLookup& lookup,
                          const ProgressCallback& progress) {
  BtfAtlases out;
  out.layout = std::move(layout);
  const int n = sample.Components();
  // Planes: sample x, sample y, angle, the factors r, g, b, then g_0 .. g_{n-1}.
  BakedPlanes baked = BakeAtlasPlanes(
      out.layout, texel_size, gutter, 6 + n,
      [&](int face, const Eigen::Vector2d& p_in_frame, float* value) {
        const BtfAtlasLookup look = lookup(face, p_in_frame);
        value[0] = static_cast<float>(look.sample_px.x());
        value[1] = static_cast<float>(look.sample_px.y());
        value[2] = static_cast<float>(WrapAngle(look.atlas_to_sample_rad));
        for (int c = 0; c < 3; ++c) value[3 + c] = look.colour_gain[c];
        btf::SampleGeometry(sample, look.sample_px, value + 6);
      },
      progress);
  for (std::vector<cv::Mat>& planes : baked.planes) {
    cv::Mat coords;
    cv::merge(std::vector<cv::Mat>(planes.begin(), planes.begin() + 3), coords);
    out.sample_coords.push_back(coords);
    cv::Mat gain;
    cv::merge(std::vector<cv::Mat>(planes.begin() + 3, planes.begin() + 6), gain);
    out.colour_gain.push_back(gain);
    out.geometry.emplace_back(planes.begin() + 6, planes.end());
  }
  out.coverage = std::move(baked.coverage);
  out.occupancy = baked.occupancy;
  return out;
}

BtfAtlases BuildBtfAtlases(const mesh::TriangleMesh& mesh, const synth::BtfMeshSynthesis& synthesis,
                           const btf::BtfFactorisation& sample, const atlas::AtlasOptions& options,
                           const ProgressCallback& progress) {
  AtlasLayout layout = atlas::LayoutAtlases(mesh, synthesis.patches, synthesis.unfoldings,
                                            synthesis.texel_size, options, progress);
  std::vector<double> face_angle;
  for (const atlas::FacePlacement& fp : layout.faces)
    face_angle.push_back(-fp.AtlasFrameAngle());  // the atlas frame's turn from the face frame
  return BakeBtfAtlases(
      std::move(layout), synthesis.texel_size, options.gutter, sample,
      [&](int face, const Eigen::Vector2d& p_in_frame) {
        const synth::BtfSampleLookup look = synthesis.Lookup(face, p_in_frame);
        // d_sample = R(look) d_face and d_face = R(-face) d_atlas.
        return BtfAtlasLookup{look.sample_px,
                              look.angle_rad - face_angle[static_cast<std::size_t>(face)],
                              look.colour_gain};
      },
      progress);
}

std::vector<ptm::Ptm> PreviewPtms(const BtfAtlases& atlases, const btf::BtfFactorisation& sample,
                                  const ProgressCallback& progress) {
  const int n = sample.Components();
  const std::vector<Eigen::Vector3d> lights = PreviewLights();
  const int count = static_cast<int>(lights.size());
  // p_i(head-on, l_j) stacked: (count * 3) x n.
  Eigen::MatrixXf appearance(count * 3, n);
  Eigen::MatrixXd basis(count, 6);
  for (int j = 0; j < count; ++j) {
    appearance.middleRows(j * 3, 3) =
        btf::InterpolateAppearance(sample, Eigen::Vector3d::UnitZ(),
                                   lights[static_cast<std::size_t>(j)])
            .transpose();
    const auto phi = ptm::PtmBasis(lights[static_cast<std::size_t>(j)].x(),
                                   lights[static_cast<std::size_t>(j)].y());
    for (int m = 0; m < 6; ++m) basis(j, m) = phi[static_cast<std::size_t>(m)];
  }
  const Eigen::MatrixXd fit = basis.completeOrthogonalDecomposition().pseudoInverse();  // 6 x J
  std::vector<ptm::Ptm> out;
  for (std::size_t a = 0; a < atlases.geometry.size(); ++a) {
    const cv::Mat& coords = atlases.sample_coords[a];
    ptm::Ptm p;
    p.Resize(ptm::PtmFormat::kLrgb, coords.cols, coords.rows);
    const auto& planes = atlases.geometry[a];
#pragma omp parallel for schedule(dynamic, 8)
    for (int y = 0; y < coords.rows; ++y) {
      Eigen::VectorXf g(n);
      Eigen::VectorXd lum(count);
      for (int x = 0; x < coords.cols; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * coords.cols + x;
        for (int i = 0; i < n; ++i) g[i] = planes[static_cast<std::size_t>(i)].at<float>(y, x);
        Eigen::VectorXf linear = appearance * g;
        const cv::Vec3f k = atlases.colour_gain[a].at<cv::Vec3f>(y, x);
        for (int j = 0; j < count; ++j)
          for (int c = 0; c < 3; ++c) linear[j * 3 + c] *= k[c];
        Eigen::Vector3d channel_sum = Eigen::Vector3d::Zero();
        for (int j = 0; j < count; ++j) {
          double s = 0.0;
          for (int c = 0; c < 3; ++c) {
            const double d = LinearToSrgb(linear[j * 3 + c]);
            channel_sum[c] += d;
            s += d;
          }
          lum[j] = s / 3.0;
        }
        Eigen::Matrix<double, 6, 1> coefficients = fit * lum;
        // Eq. 2: colour = L (R, G, B), the colour's largest channel 1.
        const double total = lum.sum();
        Eigen::Vector3d colour =
            total > 1e-9 ? Eigen::Vector3d(channel_sum / total) : Eigen::Vector3d::Ones();
        const double top = std::max(colour.maxCoeff(), 1e-6);
        colour /= top;
        coefficients *= top;
        // Into the atlas frame: its x axis is R(angle) x in the sample frame.
        coefficients = ptm::FrameRotation(coords.at<cv::Vec3f>(y, x)[2]) * coefficients;
        float* a_out = p.Coefficients(t);
        for (int m = 0; m < 6; ++m) a_out[m] = static_cast<float>(coefficients[m]);
        for (int c = 0; c < 3; ++c) p.colour[t * 3 + c] = static_cast<float>(colour[c]);
      }
    }
    out.push_back(std::move(p));
    if (progress) progress("ptm preview", a + 1, atlases.geometry.size());
  }
  return out;
}

}  // namespace texlume::atlas
