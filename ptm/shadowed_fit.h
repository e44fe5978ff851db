#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/progress.h"
#include "ptm/horizon.h"
#include "ptm/ptm.h"

namespace texlume::ptm {

/// A PTM of a sample's lit appearance and the horizon map of its relief (issue 29):
/// relit, the PTM's linear light is scaled by the horizon's visibility, down to
/// `shadow_floor` in full shadow. Both come from the RTI capture alone.
struct ShadowedPtm {
  /// Display values (as fit.h fits), fitted to the lit samples only, in the
  /// options' format (LRGB: fit.h's chromaticity, of the lit samples).
  Ptm ptm;
  /// The shadow floor is the median over the capture's shadowed samples; the height
  /// scale is that of `ptm`'s own integrated normals (ShadowingOfPtm).
  SelfShadowing shadowing;
};

struct ShadowedFitOptions {
  PtmFormat format = PtmFormat::kLrgb;
  int sectors = 16;           ///< horizon azimuths, [4, 64]
  int reach_texels = 48;      ///< how far the horizon looks, [1, 4096]
  double penumbra_deg = 4.0;  ///< width of the shadow's edge in light elevation, (0, 45]
  /// Height scales tried; the one whose horizon best predicts an inner held-out
  /// quarter of the capture's lights is kept. 0 (no shadows) among them.
  std::vector<double> height_scales = {0.0, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0};
  /// A texel lit under fewer lights than this is fitted to all its samples. >= 6.
  int min_lit_lights = 8;

  /// Throws OptionError naming the first setting out of range.
  void Check() const;
};

/// The capture's images (CV_32FC3 display RGB in [0, 1], one per light, all one
/// size) and lights (unit, texel frame, above the horizon). Steps (a class, one
/// method each): fit an RGB PTM to every sample; integrate its normals into heights
/// (HeightFromNormals); choose the height scale on an inner split of the lights;
/// refit the PTM to the samples the chosen horizon leaves lit; measure the shadow
/// floor. Throws InputError for fewer than 8 lights or images of different sizes.
ShadowedPtm FitShadowedPtm(const std::vector<cv::Mat>& images,
                           const std::vector<Eigen::Vector3d>& lights,
                           const ShadowedFitOptions& options = {},
                           const ProgressCallback& progress = {});

/// Least-squares PTM of the samples marked lit (`lit[k][texel]` 1 or 0, one vector
/// per light), every sample where fewer than `min_lit_lights` are lit. LRGB: the
/// chromaticity is fit.h's (the luminance-weighted mean colour, largest channel 1)
/// and the polynomial fits each sample's projection on it.
Ptm FitPtmToLitSamples(const std::vector<cv::Mat>& images,
                       const std::vector<Eigen::Vector3d>& lights,
                       const std::vector<std::vector<float>>& lit, PtmFormat format,
                       int min_lit_lights);

/// The PTM relit under `light` (Relight's display RGB, row-major), its linear light
/// times SelfShadowing::LightFactor. Throws std::invalid_argument when the horizon
/// map's size is not the PTM's.
std::vector<float> RelightShadowed(const Ptm& ptm, const SelfShadowing& shadowing,
                                   const Eigen::Vector3d& light);
std::vector<float> RelightShadowed(const ShadowedPtm& shadowed, const Eigen::Vector3d& light);

/// The self-shadowing of a PTM made of a sample's texels at the sample's texel size
/// (a synthesised atlas): its own normals integrated (HeightFromNormals) at the
/// sample's height scale, with the sample's sectors, shadow floor and penumbra. On
/// the fitted sample itself it gives back the fit's horizon. The horizon sees no
/// relief beyond the map, nor, given an atlas's `charts` (CV_32SC1, the chart of each
/// texel, -1 in gutters; model::AtlasChartRegions), beyond its texel's chart
/// (ComputeHorizonMap's regions): without them its rays cross a chart's gutter into
/// the next chart's relief.
SelfShadowing ShadowingOfPtm(const Ptm& ptm, const SelfShadowing& sample, int reach_texels = 48,
                             const cv::Mat& charts = cv::Mat());

}  // namespace texlume::ptm
