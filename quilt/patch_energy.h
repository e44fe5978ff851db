#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "quilt/patch_matching.h"

// How much a synthesised texture looks like its sample (issue 32's measure):
// the nearest-patch energy, the mean over windows of the texture of the
// smallest masked SSD between the window and any window of the sample at any
// of the 72 rotations (Kwatra et al. 2005's texture energy), per texel.

namespace texlume::quilt {

struct PatchEnergyOptions {
  int window = 8;      ///< window side, texels
  int windows = 48;    ///< windows measured, at random among those inside the texture
  int rotations = 72;  ///< the sample's rotations tried: every (72 / rotations)-th copy
  std::uint64_t seed = 1;
};

struct PatchEnergy {
  double per_texel = 0;  ///< mean smallest SSD per texel (feature units squared)
  int windows = 0;       ///< windows measured (fewer when the texture has fewer inside)
};

/// `planes`: the texture's feature planes in its frame (x right, y up; the
/// sample's kind, e.g. a PTM atlas's orthonormal coefficients), `inside`:
/// CV_8UC1, non-zero where the texture is defined (a window must lie wholly
/// inside). Throws std::invalid_argument when the planes are not the sample's
/// features.
PatchEnergy NearestPatchEnergy(const std::vector<cv::Mat>& planes, const cv::Mat& inside,
                               RotatedSample& sample, const PatchEnergyOptions& options = {});

}  // namespace texlume::quilt
