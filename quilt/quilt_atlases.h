#pragma once

#include <vector>

#include "atlas/atlas.h"
#include "core/progress.h"
#include "quilt/dense_surface.h"
#include "quilt/surface_quilting.h"
#include "synth/material_sample.h"

namespace texlume::quilt {

/// The PTM atlases of a quilted surface, by the common baker
/// (atlas::BakeAtlasPlanes): each texel inside a face shows its dense sample's
/// lookup; a gutter texel carries on the lookup of the nearest sample of its
/// face's chart (the patch continued, so bilinear reads across a chart's edge
/// see the texture that lies there). The sample's values (orthonormal
/// coefficients and LRGB colour, PtmSample::Values) are read at the lookup's
/// position and the coefficients turned into the atlas frame.
atlas::Atlases BakeQuiltedAtlases(const DenseSurface& surface, const QuiltResult& quilt,
                                  const atlas::AtlasLayout& layout,
                                  const std::vector<synth::TrianglePatch>& patches,
                                  const synth::PtmSample& sample, int gutter,
                                  const ProgressCallback& progress = {});

}  // namespace texlume::quilt
