#pragma once

#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "synth/material_sample.h"
#include "synth/triangle_engine.h"

// Where a face's patch goes in the sample under the image constraint of paper
// 003 (eq. 3, the RMS difference between the sample relit under a photo's
// lighting and the photo rectified into the face frame, summed over the face's
// photos): the paper's exhaustive search, every placement at the photos' density
// (by FFT, or directly where that takes fewer operations), or the search coarse to
// fine (issue 33), exhaustive only at the coarsest density and then refined around
// the best candidates.
namespace texlume::synth {

/// A placement's score (eq. 3 summed over the views) and its top-left texel in the sample.
using ScoredPlacement = std::pair<float, cv::Point>;

/// The placements of one face's patch scored against its rectified views.
class PlacementSearch {
 public:
  /// Placements scored side by side: a view's cells at (at.x + k, at.y), k < kLanes
  /// (one AVX2 register of floats, or two SSE2 ones).
  static constexpr int kLanes = RelitScratch::kPastTheSample + 1;

  /// `views` rectified at their photo density levels (best view first), `photo_gains`
  /// per photo, `patch_texels` the patch's size in sample texels. All references must
  /// outlive the search. `scratch` (optional; it must outlive the search, and serve one
  /// search at a time) lends the direct scores their buffers; without it each
  /// CoarseToFine allocates its own.
  PlacementSearch(const MaterialSample& sample, const std::vector<RectifiedView>& views,
                  const std::vector<double>& photo_gains, cv::Size patch_texels,
                  RelitScratch* scratch = nullptr);
  PlacementSearch(const PlacementSearch&) = delete;
  PlacementSearch& operator=(const PlacementSearch&) = delete;

  /// Paper 003: every placement scored (FFT), the top_k distinct ones at the primary
  /// view's density (a photo cell apart), best first.
  std::vector<ScoredPlacement> Exhaustive(int top_k) const;

  /// The same search coarse to fine: every view reduced by halves of its density
  /// (up to `max_steps` times, while the best view's grid keeps `min_cells` cells a
  /// side); every placement scored at the coarsest; then at each finer density only
  /// the placements within half a coarse cell of the `candidates` best are scored,
  /// directly.
  /// Returns the top_k at the photos' density, best first. With no coarser density
  /// possible it is Exhaustive.
  std::vector<ScoredPlacement> CoarseToFine(int top_k, int candidates, int max_steps = 3,
                                            int min_cells = 6) const;

  /// Each view's sample relit at its density around the patch placed at `at` (sample
  /// texels), `margin_cells[v]` cells beyond the patch's grid (clipped to the sample).
  std::vector<RelitWindow> RelitAround(cv::Point at, const std::vector<int>& margin_cells) const;

  /// How many coarser densities CoarseToFine would use.
  int CoarseSteps(int max_steps, int min_cells) const;

 private:
  // One view at a search step (its density level + 4 per step: half the density).
  struct ViewAtStep {
    const ReducedPlanes* reduced = nullptr;
    std::vector<cv::Mat> photo;  // R, G, B on the step's grid
    cv::Mat mask;                // CV_32FC1 weights
    double count = 0.0;          // sum of the mask
    const RectifiedView* view = nullptr;
    int placements_x = 0, placements_y = 0;  // placements at this density
    cv::Point Cell(cv::Point texel) const;   // the placement a sample texel falls in
  };
  std::vector<ViewAtStep> ViewsAtStep(int step) const;
  // The primary view's photo cell at a step, in sample texels (>= 1).
  static int Stride(const std::vector<ViewAtStep>& views);
  // Eq. 3 at every placement (FFT, or directly where that takes fewer operations:
  // the sums then differ from the FFT's in rounding), at the placements `stride`
  // texels apart.
  std::vector<ScoredPlacement> ScoreOnGrid(const std::vector<ViewAtStep>& views, int stride) const;
  // The sample relit under a view at a step, as placements ask, so that no cell is
  // relit twice however the placements overlap; and the view's scores by cell.
  class RelitView;
  // Eq. 3 at the given placements (sample texels), computed directly; `relit`
  // per view.
  std::vector<float> ScoreAt(const std::vector<ViewAtStep>& views,
                             const std::vector<cv::Point>& texels,
                             std::vector<RelitView>& relit) const;
  // Eq. 3 of view `v` alone at those cells (placements' top left); a lane past the
  // view's last placement holds nothing of use.
  std::array<double, kLanes> RowOfCellScores(const ViewAtStep& v, cv::Point at,
                                             RelitView& relit) const;
  // The sample relit under `v`'s lighting over `cells` of its reduced sample.
  std::vector<cv::Mat> RelitCells(const ViewAtStep& v, cv::Rect cells) const;

  const MaterialSample& sample_;
  const std::vector<RectifiedView>& views_;
  const std::vector<double>& photo_gains_;
  cv::Size patch_;
  RelitScratch* scratch_;        // lent, or null
  int last_x_ = 0, last_y_ = 0;  // the last placement's top-left texel
};

}  // namespace texlume::synth
