#include "quilt/quilt_atlases.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/cubic_interpolation.h"
#include "ptm/coefficient_space.h"
#include "synth/planar_synthesis.h"

namespace texlume::quilt {
namespace {

// A face's atlas pixel coordinates of a point of its frame (atlas::FacePlacement).
Eigen::Vector2d AtlasPx(const atlas::FacePlacement& fp, const Eigen::Vector2d& p_in_frame,
                        double texel_size) {
  const Eigen::Vector2d r = fp.linear * p_in_frame / texel_size;
  return {fp.offset.x() + r.x(), fp.offset.y() - r.y()};
}

// The quilted sample of the face's chart whose texel centre is nearest to px,
// within `reach` texels; -1 when none is.
int NearestSample(const DenseSurface& surface, const QuiltResult& quilt,
                  const atlas::FacePlacement& fp, const Eigen::Vector2d& px, int reach) {
  const auto usable = [&](int s) {
    return s >= 0 && surface.samples()[static_cast<std::size_t>(s)].chart == fp.chart &&
           quilt.lookups[static_cast<std::size_t>(s)].synthesised;
  };
  const int x0 = static_cast<int>(std::floor(px.x())), y0 = static_cast<int>(std::floor(px.y()));
  const int own = surface.At(fp.atlas, x0, y0);
  if (usable(own)) return own;
  int best = -1;
  double best_d2 = std::numeric_limits<double>::max();
  for (int y = y0 - reach; y <= y0 + reach; ++y)
    for (int x = x0 - reach; x <= x0 + reach; ++x) {
      const int s = surface.At(fp.atlas, x, y);
      if (!usable(s)) continue;
      const double d2 = (Eigen::Vector2d(x + 0.5, y + 0.5) - px).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = s;
    }
  return best;
}

}  // namespace

void SampleValuesTurned(const std::vector<cv::Mat>& values, int polynomials,
                        const Eigen::Vector2d& sample_px, double turn_rad, float* out) {
  const CatmullRomTaps taps(values[0].size(), sample_px.x() - 0.5, sample_px.y() - 0.5);
  for (std::size_t k = 0; k < values.size(); ++k) out[k] = static_cast<float>(taps.Of(values[k]));
  const Eigen::Matrix<double, 6, 6> turn = ptm::OrthonormalFrameRotation(turn_rad);
  for (int poly = 0; poly < polynomials; ++poly) {
    Eigen::Map<Eigen::Matrix<float, 6, 1>> c(out + poly * 6);
    c = (turn * c.cast<double>()).cast<float>();
  }
}

QuiltedSurfaceLookup::QuiltedSurfaceLookup(const DenseSurface& surface, const QuiltResult& quilt,
                                           const atlas::AtlasLayout& layout, int gutter)
    : surface_(surface), quilt_(quilt), layout_(layout), reach_(gutter + 2) {}

bool QuiltedSurfaceLookup::At(int face, const Eigen::Vector2d& p_in_frame,
                              Eigen::Vector2d* sample_px, double* angle_rad) const {
  const atlas::FacePlacement& fp = layout_.faces[static_cast<std::size_t>(face)];
  const Eigen::Vector2d px = AtlasPx(fp, p_in_frame, surface_.texel_size());
  const int s = NearestSample(surface_, quilt_, fp, px, reach_);
  if (s < 0) return false;
  const DenseSample& d = surface_.samples()[static_cast<std::size_t>(s)];
  const SampleLookup& lookup = quilt_.lookups[static_cast<std::size_t>(s)];
  // The sample is turned by `angle` against the atlas frame: an atlas offset
  // (rows down) is the sample offset turned back by it.
  const double a = lookup.angle_rad, c = std::cos(a), sn = std::sin(a);
  const Eigen::Vector2d v = px - Eigen::Vector2d(d.x + 0.5, d.y + 0.5);
  *sample_px = lookup.sample_px.cast<double>() +
               Eigen::Vector2d(c * v.x() - sn * v.y(), sn * v.x() + c * v.y());
  *angle_rad = a;
  return true;
}

atlas::Atlases BakeQuiltedAtlases(const DenseSurface& surface, const QuiltResult& quilt,
                                  const atlas::AtlasLayout& layout,
                                  const std::vector<synth::TrianglePatch>& patches,
                                  const synth::PtmSample& sample, int gutter,
                                  const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  const QuiltedSurfaceLookup lookup(surface, quilt, layout, gutter);
  const std::vector<cv::Mat>& values = sample.Values();
  const int num_planes = static_cast<int>(values.size());
  const int polynomials = sample.CoefficientPlanes() / 6;
  atlas::BakedPlanes baked = atlas::BakeAtlasPlanes(
      layout, surface.texel_size(), gutter, num_planes,
      [&](int face, const Eigen::Vector2d& p_in_frame, float* out) {
        Eigen::Vector2d at;
        double a = 0;
        if (!lookup.At(face, p_in_frame, &at, &a)) {
          std::fill_n(out, num_planes, 0.0f);
          return;
        }
        SampleValuesTurned(values, polynomials, at, -a, out);
      },
      progress);
  atlas::Atlases atlases;
  atlases.num_charts = layout.num_charts;
  atlases.flattening = layout.flattening;
  atlases.faces = layout.faces;
  atlases.stretch = atlas::MeasureStretch(patches, layout);
  for (const std::vector<cv::Mat>& planes : baked.planes)
    atlases.ptms.push_back(synth::FromOrthonormalPlanes(planes, sample.format()));
  atlases.coverage = std::move(baked.coverage);
  atlases.occupancy = baked.occupancy;
  atlases.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return atlases;
}

atlas::BtfAtlases BakeQuiltedBtfAtlases(const DenseSurface& surface, const QuiltResult& quilt,
                                        const atlas::AtlasLayout& layout,
                                        const btf::BtfFactorisation& sample, int gutter,
                                        const ProgressCallback& progress) {
  const QuiltedSurfaceLookup lookup(surface, quilt, layout, gutter);
  return atlas::BakeBtfAtlases(
      layout, surface.texel_size(), gutter, sample,
      [&](int face, const Eigen::Vector2d& p_in_frame) {
        atlas::BtfAtlasLookup out;
        double a = 0;
        // The sample turned by a in the atlas frame: an atlas direction is
        // turned by -a in the sample's.
        if (lookup.At(face, p_in_frame, &out.sample_px, &a)) out.atlas_to_sample_rad = -a;
        return out;
      },
      progress);
}

}  // namespace texlume::quilt
