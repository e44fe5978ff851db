#pragma once

#include <array>
#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "core/progress.h"
#include "synth/material_sample.h"
#include "synth/triangle_parts.h"

namespace texlume::synth {

/// Graph-cut seams across every shared mesh edge, the engine's "stitch" stage
/// for a sample that is cut, not blended (paper 004 §V, Fig. 8, after Kwatra
/// et al. 2003): in a band of `seam_band` texels on both sides of the edge,
/// each texel shows one of the two faces' patches, chosen by a minimum cut of
/// E_smooth's V(p, q) = |f_A(p) - f_B(p)| + |f_A(q) - f_B(q)| over the sample's
/// feature planes; texels next to the band's outside keep their own patch.
struct SeamCut {
  /// Per face, CV_8UC1 over its patch rectangle (height x width, rows down):
  /// 0 = the face's own patch, 1 + k = the patch of the neighbour across edge k.
  std::vector<cv::Mat> labels;
  std::size_t seam_edges = 0;           ///< mesh edges with a graph cut
  std::size_t seam_links = 0;           ///< texel pairs the seams cut
  double seam_cost = 0, edge_cost = 0;  ///< totals of the two below
  double seam_cost_per_link = 0;        ///< mean V of a cut pair (feature units)
  double edge_cost_per_link = 0;        ///< the same for a straight seam along the mesh edge
  double seconds = 0;
};

/// Cuts the seams of placed patches (TriangleSynthesis::patches, texels of
/// `texel_size` world units) across their unfoldings.
SeamCut CutSeams(const std::vector<TrianglePatch>& patches,
                 const std::vector<std::array<Unfolding, 3>>& unfoldings, double texel_size,
                 const MaterialSample& sample, int seam_band,
                 const ProgressCallback& progress = {});

}  // namespace texlume::synth
