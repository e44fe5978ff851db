#pragma once

#include <Eigen/Core>
#include <vector>

#include "atlas/atlas.h"
#include "atlas/btf_atlas.h"
#include "btf/btf.h"
#include "core/progress.h"
#include "quilt/dense_surface.h"
#include "quilt/surface_quilting.h"
#include "synth/material_sample.h"

namespace texlume::quilt {

/// Where a point of a quilted surface's atlases reads the sample: the lookup of
/// the nearest quilted dense sample of the face's chart, continued to the point
/// (so a gutter texel carries on the patch, and bilinear reads across a chart's
/// edge see the texture that lies there).
class QuiltedSurfaceLookup {
 public:
  QuiltedSurfaceLookup(const DenseSurface& surface, const QuiltResult& quilt,
                       const atlas::AtlasLayout& layout, int gutter);
  /// The sample position (texels, x right, y down, centres at +0.5) and the
  /// sample's turn against the atlas frame (SampleLookup::angle_rad) at a point
  /// of a face's frame; false when no sample of the chart lies within the gutter.
  bool At(int face, const Eigen::Vector2d& p_in_frame, Eigen::Vector2d* sample_px,
          double* angle_rad) const;

 private:
  const DenseSurface& surface_;
  const QuiltResult& quilt_;
  const atlas::AtlasLayout& layout_;
  int reach_;
};

/// A PTM sample's values (orthonormal coefficients, then LRGB colour: `values`,
/// PtmSample::Values) at a sample position (texels, centres at +0.5), Catmull-Rom
/// and clamped (core/cubic_interpolation.h), with the coefficients of each of `polynomials`
/// polynomials taken into a frame turned by `turn_rad` (ptm::OrthonormalFrameRotation).
void SampleValuesTurned(const std::vector<cv::Mat>& values, int polynomials,
                        const Eigen::Vector2d& sample_px, double turn_rad, float* out);

/// The PTM atlases of a quilted surface, by the common baker
/// (atlas::BakeAtlasPlanes) through QuiltedSurfaceLookup. The sample's values (orthonormal
/// coefficients and LRGB colour, PtmSample::Values) are read at the lookup's
/// position and the coefficients turned into the atlas frame.
atlas::Atlases BakeQuiltedAtlases(const DenseSurface& surface, const QuiltResult& quilt,
                                  const atlas::AtlasLayout& layout,
                                  const std::vector<synth::TrianglePatch>& patches,
                                  const synth::PtmSample& sample, int gutter,
                                  const ProgressCallback& progress = {});

/// The BTF atlases of a quilted surface (atlas::BakeBtfAtlases through
/// QuiltedSurfaceLookup): per texel the sample position and the atlas frame's
/// turn into the sample's; no photo-consistency factors (all 1).
atlas::BtfAtlases BakeQuiltedBtfAtlases(const DenseSurface& surface, const QuiltResult& quilt,
                                        const atlas::AtlasLayout& layout,
                                        const btf::BtfFactorisation& sample, int gutter,
                                        const ProgressCallback& progress = {});

}  // namespace texlume::quilt
