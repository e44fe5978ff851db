#pragma once

#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "synth/material_sample.h"
#include "synth/nearest_windows.h"
#include "synth/triangle_engine.h"

// Detail transfer (beyond paper 003, the photo-consistency pass's last step,
// synth/coefficient_correction.h): a corrected patch's coarse luminance
// coefficients matched, cell by cell, to the sample point whose coarse window is
// nearest, whose detail band the patch then carries.
namespace texlume::synth {

/// Detail transfer's dictionary at one density level: the sample's coarse
/// luminance coefficients (orthonormal) at that density, and the window of them
/// around every sample point, 3 x 3 points one photo cell apart (read bilinearly
/// there), indexed for nearest-neighbour search. Its detail band (the planes minus
/// their coarse version brought back to full size) is what the transferred patches
/// read.
class DetailDictionary {
 public:
  /// The dictionary of `sample` reduced to density `level`; `band` receives the
  /// detail band (sample.Values()' planes interleaved: CV_32FC(planes)). Touches
  /// no shared state, so levels can be built in parallel.
  DetailDictionary(const PtmSample& sample, int level, cv::Mat& band);
  ~DetailDictionary();
  DetailDictionary(const DetailDictionary&) = delete;
  DetailDictionary& operator=(const DetailDictionary&) = delete;

  /// False when the windows are wider than the sample: no transfer.
  bool Usable() const { return nearest_ != nullptr; }

  /// Per cell of a corrected patch's grid (patch.correction, at `level`'s density),
  /// the sample point its detail comes from (patch.detail_source, texels): the
  /// index is asked at the cells of one colour of a checkerboard (issue 33: half
  /// the queries); passes then take a neighbour cell's match moved by one cell
  /// wherever it is nearer (the other cells' only matches, unless they lie beyond
  /// the neighbours' reach and ask the index themselves). Only the cells `wanted`
  /// marks (CellsReadWithin; empty: every cell) are matched; the others keep their
  /// own place in the sample (the patch's own detail).
  void Transfer(TrianglePatch& patch, int level, const cv::Mat& wanted = cv::Mat()) const;

 private:
  // Per cell of a patch's grid (row-major): the sample point its detail comes from
  // (texels) and the squared window distance (infinite: none yet).
  struct Matches {
    Matches(int w, int h)
        : width(w),
          source(static_cast<std::size_t>(w * h)),
          distance(static_cast<std::size_t>(w * h), std::numeric_limits<float>::infinity()) {}
    bool Found(std::size_t c) const { return distance[c] < std::numeric_limits<float>::infinity(); }
    int width;
    std::vector<cv::Vec2f> source;
    std::vector<float> distance;
  };
  // The first 6 of `raw_planes` (raw luminance coefficients) in the orthonormal
  // basis, interleaved (kPointFloats a point).
  static cv::Mat ToOrthonormalPoints(const std::vector<cv::Mat>& raw_planes);
  // The detail band: `values` minus their coarse version `coarse_raw` (the raw
  // planes brought back to full size; the luminance's in the orthonormal basis).
  static void DetailBand(const std::vector<cv::Mat>& values, const std::vector<cv::Mat>& coarse_raw,
                         cv::Mat& band);
  void IndexWindows();
  // Cell (i, j) of a patch's correction grid at its own place in the sample (texels,
  // centres at integers).
  cv::Point2d CellInSample(const TrianglePatch& patch, int i, int j) const {
    return {patch.sample_x + (i + 0.5) * dx_ - 0.5, patch.sample_y + (j + 0.5) * dy_ - 0.5};
  }
  // A sample position (texels, centres at integers) in coarse_'s pixels.
  cv::Point2d OnCoarse(double x, double y) const {
    return {(x + 0.5) * rx_ - 0.5, (y + 0.5) * ry_ - 0.5};
  }
  // Per cell, the window of the corrected coarse coefficients (a row each).
  cv::Mat CorrectedWindows(const TrianglePatch& patch) const;
  // The nearest windows of the index for `cells` (row-major indices).
  void MatchByIndex(const cv::Mat& windows, const std::vector<int>& cells, Matches& matches) const;
  // One pass over the grid (forward: from the left and above; else from the right
  // and below) taking a neighbour's match moved by one cell wherever it is nearer,
  // into the cells `wanted` marks (empty: every cell).
  void Propagate(const cv::Mat& windows, bool forward, const cv::Mat& wanted,
                 Matches& matches) const;

  // The windows around points_, read from coarse_ as the index asks (none held).
  class PointWindows;

  double dx_ = 1.0, dy_ = 1.0;  // texels per photo cell
  double rx_ = 1.0, ry_ = 1.0;  // photo cells per texel
  cv::Size full_;               // the sample's size, texels
  // The 6 orthonormal luminance planes interleaved (8 floats a point), at the
  // photo's density (a pixel a photo cell: the windows' points fall on its grid).
  cv::Mat coarse_;
  std::vector<cv::Point> points_;  // window centres, texels
  std::unique_ptr<PointWindows> windows_;
  std::unique_ptr<NearestWindows> nearest_;
};

/// The cells of a corrected patch's grid whose detail a read of the patch within
/// `reach_texels` of its triangle takes (SamplePtmPatch reads the 4 cells around a
/// texel), 1 each (CV_8UC1, the grid's size, with a margin of half a cell); empty
/// (every cell) when the reach is negative.
cv::Mat CellsReadWithin(const TrianglePatch& patch, double texel_size, double reach_texels);

}  // namespace texlume::synth
