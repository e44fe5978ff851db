// The work patch P(v) and its work image I(v) (paper 004 §III-B, steps 2 and 3):
// the samples a breadth-first traversal reaches from a seed, laid flat in one
// image, inside one chart by the chart itself and across charts by the
// least-squares conformal map of the faces under them.
#pragma once

#include <Eigen/Core>
#include <unordered_map>
#include <vector>

#include "atlas/atlas.h"
#include "quilt/dense_surface.h"

namespace texlume::quilt {

/// One sample of a work patch: where it lies in the work image (pixels, rows
/// down, continuous) and how its chart's atlas frame turns into the work frame
/// (radians, counter-clockwise with y up).
struct PatchSample {
  int sample = 0;
  Eigen::Vector2d w = Eigen::Vector2d::Zero();
  double chart_to_work_rad = 0;
};

struct WorkPatch {
  bool fits = false;                                 ///< the work image fits in the sample's copies
  double distortion = 0.0;                           ///< its area distortion (T_d)
  std::vector<PatchSample> samples;                  ///< the seed first
  std::unordered_map<int, int> local;                ///< dense sample -> index in samples
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< the image's pixel (0, 0), work pixels
  int width = 0, height = 0;                         ///< the work image, pixels
};

/// Builds work patches over a dense surface for copies of `copy_side` texels.
class WorkPatchBuilder {
 public:
  /// `conformal`: flatten patches across charts by LSCM (the paper); else keep
  /// the charts' rigid maps (an ablation).
  WorkPatchBuilder(const DenseSurface& surface, const atlas::AtlasLayout& layout, int copy_side,
                   bool conformal);

  /// P(v), `levels` deep, with whether its image fits the copies and its area
  /// distortion.
  WorkPatch Build(int v, int levels) const;
  /// Keeps the samples of the patch within the copies' reach of the seed (the
  /// smallest patch, when a chart's turn makes it wider than its levels).
  void TrimToCopySide(WorkPatch& patch) const;

 private:
  void FlattenConformally(WorkPatch& patch) const;
  Eigen::Vector2d StepPx(int a, int b) const;
  double TurnBetween(int b, int a) const;
  bool FrameWorkImage(WorkPatch& patch) const;
  double AreaDistortion(const WorkPatch& patch) const;

  const DenseSurface& surface_;
  const atlas::AtlasLayout& layout_;
  const int copy_side_;
  const bool conformal_;
  std::vector<Eigen::Vector3d> atlas_x_, atlas_y_, normal_;  ///< per face, world
};

}  // namespace texlume::quilt
